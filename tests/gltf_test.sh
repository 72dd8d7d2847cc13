#!/bin/bash
# Tests of the glTF export tool sfb2gltf: usage and bad input (exit codes, messages, no partial
# output), every export checked by the Khronos glTF-Validator (0 errors, 0 warnings: every peer
# shape, the examples, the real meshes, every scheme and option), and read back with tinygltf
# against the library's own output (build/gltf_check: positions, normals, UVs, counts, split
# hard edges). --fillet (seed 002's rolling-ball fillets before the export): usage and bad input,
# the input's triangle count kept, --crease-angle as the feature angle, and the export read back
# against the library's surface of `surfblend fillet`'s mesh.
set -u
BUILD=${BUILD:-build}
SHAPES=${SHAPES:-../shared/peers/opensubdiv-shapes}
REAL=${REAL:-$(dirname "$SHAPES")/real-meshes}
TOOL=$BUILD/sfb2gltf
CHECK=$BUILD/gltf_check
# the validator wrapper (tests/web/validate.mjs, npm gltf-validator installed by make deps-web)
VALIDATE=${VALIDATE:-node tests/web/validate.mjs}
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
P=0; F=0; S=0
ok() { P=$((P + 1)); echo "ok $1"; }
bad() { F=$((F + 1)); echo "FAIL $1"; }
check() { # description, expected exit code, command...
  local desc=$1 want=$2; shift 2
  "$@" > "$TMP/out" 2> "$TMP/err"; local got=$?
  if [ "$got" = "$want" ]; then ok "$desc"; else bad "$desc: exit $got, wanted $want"; head -n 5 "$TMP/err"; fi
}
contains() { # description, file, pattern
  if grep -qi -- "$3" "$2"; then ok "$1"; else bad "$1: '$3' not in output"; head -n 5 "$2"; fi
}
absent() { # description, file
  if [ ! -e "$2" ]; then ok "$1"; else bad "$1: $2 exists"; fi
}
# gltf_check's PASS/FAIL lines into the counts
count_check() {
  local out; out=$("$CHECK" "$@" 2>&1)
  P=$((P + $(grep -c '^PASS' <<< "$out"))); local f; f=$(grep -c '^FAIL' <<< "$out"); F=$((F + f))
  [ "$f" -gt 0 ] && grep '^FAIL' <<< "$out"
  grep -q 'passed,' <<< "$out" || { bad "gltf_check $1 did not finish"; echo "$out" | tail -3; }
}

BOX=examples/data/creased_box.obj
# ---- usage ----
check "--help succeeds" 0 "$TOOL" --help
contains "--help lists --crease-angle" "$TMP/out" "--crease-angle"
contains "--help lists --tess" "$TMP/out" "--tess RATE"
contains "--help lists --fillet" "$TMP/out" "--fillet R"
check "--version succeeds" 0 "$TOOL" --version
contains "--version names surfblend" "$TMP/out" "surfblend"
check "no arguments is a usage error" 2 "$TOOL"
check "no output is a usage error" 2 "$TOOL" "$BOX"
check "an unknown option is a usage error" 2 "$TOOL" --frobnicate "$BOX" -o "$TMP/x.glb"
check "a bad --level is a usage error" 2 "$TOOL" --level x "$BOX" -o "$TMP/x.glb"
check "--level with --tess is a usage error" 2 "$TOOL" --level 2 --tess 4 "$BOX" -o "$TMP/x.glb"
check "--tess 0 is a usage error" 2 "$TOOL" --tess 0 "$BOX" -o "$TMP/x.glb"
check "--tess 1025 is a usage error" 2 "$TOOL" --tess 1025 "$BOX" -o "$TMP/x.glb"
check "--trim without --tess is a usage error" 2 "$TOOL" --trim examples/data/trim_disc.png "$BOX" -o "$TMP/x.glb"
check "--normals shading on bilinear is a usage error" 2 "$TOOL" --scheme bilinear --normals shading "$BOX" -o "$TMP/x.glb"
check "--normals shading with --tess is a usage error" 2 "$TOOL" --tess 4 --normals shading "$BOX" -o "$TMP/x.glb"
check "--crease-angle 200 is a usage error" 2 "$TOOL" --crease-angle 200 "$BOX" -o "$TMP/x.glb"
check "an unknown scheme is a usage error" 2 "$TOOL" --scheme nosuch "$BOX" -o "$TMP/x.glb"
absent "usage errors leave no output" "$TMP/x.glb"
check "tribezier (seed 004) is exported tessellated" 0 "$TOOL" --scheme tribezier --tess 4 examples/data/tribezier_crease_v5.obj -o "$TMP/tbz.glb"
check "tribezier --sharpness 0.5 is exported" 0 "$TOOL" --scheme tribezier --sharpness 0.5 --tess 4 examples/data/tribezier_crease_v5.obj -o "$TMP/tbz5.glb"
if [ -f "$TMP/tbz.glb" ] && [ -f "$TMP/tbz5.glb" ] && ! cmp -s "$TMP/tbz.glb" "$TMP/tbz5.glb"; then ok "--sharpness changes the tribezier surface"
else bad "--sharpness 0.5 wrote the same file as the tags' s = 1"; fi
check "--sharpness outside [0, 1] is a usage error (exit 2)" 2 "$TOOL" --scheme tribezier --sharpness 1.5 --tess 4 examples/data/tribezier_crease_v5.obj -o "$TMP/tbzbad.glb"
check "--sharpness on another scheme is a usage error (exit 2)" 2 "$TOOL" --scheme loop --sharpness 0.5 examples/data/tribezier_crease_v5.obj -o "$TMP/tbzbad.glb"
absent "a refused --sharpness leaves no output" "$TMP/tbzbad.glb"
check "tribezier refuses quads (exit 1)" 1 "$TOOL" --scheme tribezier --tess 4 "$BOX" -o "$TMP/tbzq.glb"
absent "a refused tribezier export leaves no output" "$TMP/tbzq.glb"

# ---- bad input: exit 1, one line naming the file, no output file ----
badcase() { # description, pattern the message must contain, input, options...
  local desc=$1 pat=$2 in=$3; shift 3
  rm -f "$TMP/o.glb"
  check "$desc is bad input" 1 "$TOOL" "$@" "$in" -o "$TMP/o.glb"
  contains "$desc: the message names the problem" "$TMP/err" "$pat"
  absent "$desc: no output file" "$TMP/o.glb"
  if [ "$(wc -l < "$TMP/err")" -le 2 ]; then ok "$desc: the message is short"; else bad "$desc: $(wc -l < "$TMP/err") lines of messages"; fi
}
badcase "a missing file" "does-not-exist" "$TMP/does-not-exist.obj"
printf '\x00\x01\x02binary junk\xff' > "$TMP/junk.obj"
badcase "a binary file" "junk.obj" "$TMP/junk.obj"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n' > "$TMP/range.obj"
badcase "an out-of-range index" "line 4" "$TMP/range.obj"
printf 'v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n' > "$TMP/nan.obj"
badcase "a NaN coordinate" "finite" "$TMP/nan.obj"
printf '# nothing\n' > "$TMP/empty.obj"
badcase "a file with no faces" "empty.obj" "$TMP/empty.obj"
printf 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\nt hole 1/0/0 0\n' > "$TMP/allhole.obj"
badcase "a mesh whose every face is a hole" "no triangles" "$TMP/allhole.obj"
badcase "a level over the limit" "limit" "$BOX" --level 11
badcase "Loop on quads" "triangles" "$BOX" --scheme loop
badcase "a missing trimming mask" "mask" "$BOX" --tess 4 --trim "$TMP/none.png"
check "an unwritable output is bad input" 1 "$TOOL" "$BOX" -o "$TMP/no/such/dir/x.glb"
contains "the unwritable output is named" "$TMP/err" "no/such/dir"
echo keep > "$TMP/keep.glb"
check "a failed export" 1 "$TOOL" --level 11 "$BOX" -o "$TMP/keep.glb"
if [ "$(cat "$TMP/keep.glb")" = keep ]; then ok "a failed export leaves an existing file untouched"; else bad "a failed export changed the existing file"; fi
check "a failed .gltf export" 1 "$TOOL" --level 11 "$BOX" -o "$TMP/f.gltf"
absent "a failed .gltf export leaves no .gltf" "$TMP/f.gltf"
absent "a failed .gltf export leaves no .bin" "$TMP/f.bin"
if ls "$TMP" | grep -q '\.tmp\|^\.'; then bad "temporary files left behind: $(ls -a "$TMP" | tr '\n' ' ')"; else ok "no temporary files left behind"; fi

# ---- exports ----
mkdir -p "$TMP/v"
export_ok() { # name, input, options...: writes $TMP/v/NAME
  local name=$1 in=$2; shift 2
  [ -e "$in" ] || { S=$((S + 1)); echo "SKIP export $name: $in is not here (the sanitizer run's reduced shape set)"; return; }
  check "export $name" 0 "$TOOL" -q "$@" "$in" -o "$TMP/v/$name"
}
export_ok box.glb "$BOX"
export_ok box.gltf "$BOX"
export_ok box_flat.glb "$BOX" --normals flat
export_ok box_limit.glb "$BOX" --normals limit
export_ok box_tess.glb "$BOX" --tess 8
export_ok box_adaptive.glb "$BOX" --tess 32 --tolerance 0.002
export_ok box_noopt.glb "$BOX" --no-optimize
export_ok box_quant.glb "$BOX" --quantize
export_ok box_quant16.gltf "$BOX" --quantize --position-bits 16 --normal-bits 16 --uv-bits 16
export_ok torus_quant_tess.glb examples/data/torus.obj --tess 6 --quantize --normal-bits 10
export_ok box_compress.glb "$BOX" --compress
# quads made triangles (sfb_mesh_triangulate) for the triangle schemes: the creased box's tags kept
export_ok box_tribezier_triangulated.glb "$BOX" --scheme tribezier --tess 4 --triangulate
# the sharpness slider as a glTF morph target (--sharpness-morph): the base at s = 0, one target
# to s = 1, default weight 0.5; read back at weights 0 and 1 (the library's surface there, normals
# included) and 0.5 (positions exact, the blended normals within 5 degrees: printed)
TBZ=examples/data/tribezier_crease_v5.obj
check "tribezier --sharpness-morph is exported" 0 "$TOOL" -q --scheme tribezier --tess 8 --sharpness-morph --sharpness 0.5 "$TBZ" -o "$TMP/v/tbz_morph.glb"
for w in 0 1; do count_check "$TMP/v/tbz_morph.glb" "$TBZ" --scheme tribezier --tess 8 --sharpness 0.5 --morph $w --morph-degrees 0.001; done
count_check "$TMP/v/tbz_morph.glb" "$TBZ" --scheme tribezier --tess 8 --sharpness 0.5 --morph 0.5 --morph-degrees 5
"$CHECK" "$TMP/v/tbz_morph.glb" "$TBZ" --scheme tribezier --tess 8 --sharpness 0.5 --morph 0.5 | grep "blended normals"
check "--sharpness-morph on another scheme is a usage error (exit 2)" 2 "$TOOL" --scheme loop --sharpness-morph "$TBZ" -o "$TMP/x.glb"
# quantized (KHR_mesh_quantization: the target in grid steps): within half a step at every weight,
# the 8-bit normals within 1 degree at the ends
check "tribezier --sharpness-morph --quantize is exported" 0 "$TOOL" -q --scheme tribezier --tess 8 --sharpness-morph --quantize "$TBZ" -o "$TMP/v/tbz_morph_q.glb"
for w in 0 1; do count_check "$TMP/v/tbz_morph_q.glb" "$TBZ" --scheme tribezier --tess 8 --quantize --morph $w --morph-degrees 1; done
count_check "$TMP/v/tbz_morph_q.glb" "$TBZ" --scheme tribezier --tess 8 --quantize --morph 0.5 --morph-degrees 5
check "--sharpness-morph with --compress is a usage error (exit 2)" 2 "$TOOL" --scheme tribezier --tess 8 --sharpness-morph --quantize --compress "$TBZ" -o "$TMP/x.glb"
check "--sharpness-morph with --tolerance is a usage error (exit 2)" 2 "$TOOL" --scheme tribezier --tess 8 --tolerance 0.01 --sharpness-morph "$TBZ" -o "$TMP/x.glb"
export_ok box_pn_triangulated.glb "$BOX" --scheme pn --tess 4 --triangulate
export_ok box_loop_triangulated.glb "$BOX" --scheme loop --level 2 --triangulate
export_ok box_compress_quant.glb "$BOX" --compress --quantize
export_ok box_compress_quant.gltf "$BOX" --compress --quantize
a=$(stat -c %s "$TMP/v/box.glb"); b=$(stat -c %s "$TMP/v/box_compress_quant.glb")
if [ "$b" -lt "$a" ]; then ok "--compress --quantize is smaller ($b bytes, plain $a)"; else bad "--compress --quantize: $b bytes, plain $a"; fi
check "--normal-bits without --quantize is a usage error" 2 "$TOOL" --normal-bits 10 "$BOX" -o "$TMP/x.glb"
check "--position-bits 17 is a usage error" 2 "$TOOL" --quantize --position-bits 17 "$BOX" -o "$TMP/x.glb"
export_ok box_bilinear.glb "$BOX" --scheme bilinear --level 2
export_ok box_gltf_flag.json "$BOX" --gltf
check "--gltf with a .glb name is a usage error" 2 "$TOOL" --gltf "$BOX" -o "$TMP/v/x.glb"
export_ok manifold.glb examples/data/manifold_features.obj --scheme manifold
export_ok manifold_trim.glb examples/data/manifold_features.obj --scheme manifold --tess 24 --trim examples/data/trim_disc.png
export_ok torus.glb examples/data/torus.obj
export_ok torus_tess_flat.glb examples/data/torus.obj --tess 6 --normals flat
check "export with --progress" 0 "$TOOL" --progress "$BOX" -o "$TMP/v/box_progress.glb"
contains "--progress draws the stages" "$TMP/err" "\[5/5\] write"
check "a summary line by default" 0 "$TOOL" "$BOX" -o "$TMP/v/box_summary.glb"
contains "the summary gives the triangles" "$TMP/err" "triangles"
if [ -f "$TMP/v/box.bin" ] && grep -q '"uri": "box.bin"' "$TMP/v/box.gltf"; then ok ".gltf refers to its .bin"; else bad ".gltf without its .bin"; fi
mv "$TMP/v/box_gltf_flag.json" "$TMP/v/box_gltf_flag.gltf"
if [ -f "$TMP/v/box_gltf_flag.bin" ] && head -c 1 "$TMP/v/box_gltf_flag.gltf" | grep -q '{'; then ok "--gltf writes JSON and a .bin"; else bad "--gltf did not write JSON + .bin"; fi
if [ "$(head -c 4 "$TMP/v/box.glb")" = glTF ]; then ok ".glb is binary glTF"; else bad ".glb does not start with glTF"; fi
# --lods: one mesh and node per level (or rate)
check "--lods 1,2,3" 0 "$TOOL" --lods 1,2,3 --gltf "$BOX" -o "$TMP/v/lods.gltf"
contains "--lods writes three meshes" "$TMP/err" "3 meshes"
for l in 1 2 3; do contains "--lods: a node for level $l" "$TMP/v/lods.gltf" "\"creased_box level $l\""; done
# MSFT_lod: the scene's node shows the most detailed LOD alone, which names the others from the
# most detailed down; the extension is used, not required
check "--lods 2,3,1 (out of order)" 0 "$TOOL" --lods 2,3,1 --gltf "$BOX" -o "$TMP/v/lods_msft.gltf"
lodtree=$(node -e '
  const j = JSON.parse(require("fs").readFileSync(process.argv[1], "utf8")), n = j.nodes, root = n[j.scenes[0].nodes[0]];
  const top = n[root.children[0]], ids = ((top.extensions || {}).MSFT_lod || {}).ids || [];
  console.log([root.children.length, top.name, ids.map(i => n[i].name).join("+"), (j.extensionsUsed || []).includes("MSFT_lod"),
               (j.extensionsRequired || []).includes("MSFT_lod")].join("|"));' "$TMP/v/lods_msft.gltf" 2>&1)
if [ "$lodtree" = "1|creased_box level 3|creased_box level 2+creased_box level 1|true|false" ]; then ok "--lods: MSFT_lod from the most detailed LOD"
else bad "--lods: MSFT_lod tree: $lodtree"; fi
check "--lods with --tess gives rates" 0 "$TOOL" --tess 1 --lods 2,6 --gltf "$BOX" -o "$TMP/v/lods_tess.gltf"
contains "--lods --tess: a node for rate 6" "$TMP/v/lods_tess.gltf" "rate 6"
export_ok lods_quant.glb "$BOX" --lods 0,2 --quantize --compress
check "--lods with --level is a usage error" 2 "$TOOL" --lods 1,2 --level 2 "$BOX" -o "$TMP/x.glb"
check "--lods 1,x is a usage error" 2 "$TOOL" --lods 1,x "$BOX" -o "$TMP/x.glb"
badcase "--lods over the level limit" "limit" "$BOX" --lods 1,11

# --report: the deviation from the exact limit surface (the summary line gives the maxima)
report() { # description, max position error wanted (awk condition on p), on the normal error (n), options...
  local desc=$1 pc=$2 nc=$3; shift 3
  check "$desc: export with --report" 0 "$TOOL" "$@" --report "$TMP/v/report.json" "$BOX" -o "$TMP/v/report.glb"
  local line p n
  line=$(grep "deviation from the limit surface" "$TMP/err")
  p=$(sed -nE 's/.*positions up to ([^ ]+) .*/\1/p' <<< "$line"); n=$(sed -nE 's/.*normals up to ([^ ]+) degrees.*/\1/p' <<< "$line")
  if [ -n "$p" ] && awk -v p="$p" -v n="$n" "BEGIN { exit !(($pc) && ($nc)) }"; then ok "$desc: positions $p, normals $n degrees"
  else bad "$desc: positions '$p', normals '$n' degrees (wanted $pc, $nc)"; fi
  contains "$desc: the report has the normal error" "$TMP/v/report.json" '"normal_error_degrees"'
}
report "tessellated, float" "p == 0" "n < 1e-3" --tess 6
report "tessellated, quantized" "p > 0 && p < 3e-4" "n > 0.01 && n < 1" --tess 6 --quantize
report "tessellated, 16-bit quantized" "p > 0 && p < 5e-5" "n < 0.01" --tess 6 --quantize --position-bits 16 --normal-bits 16
report "refined (against the limit points)" "p > 1e-3" "n >= 0" --level 2
check "--report into a missing folder fails" 1 "$TOOL" --report "$TMP/no/dir/r.json" "$BOX" -o "$TMP/v/r2.glb"
rm -f "$TMP/v/report.glb" "$TMP/v/r2.glb"

# the peer shapes (Catmull-Clark, Loop, bilinear; UVs, holes, non-manifold) at level 2
n=0
if [ -d "$SHAPES" ]; then
  for f in "$SHAPES"/*.obj; do
    b=$(basename "$f" .obj)
    if "$TOOL" -q --level 2 "$f" -o "$TMP/v/peer_$b.glb" 2> "$TMP/err"; then n=$((n + 1)); else bad "export peer $b: $(head -n 1 "$TMP/err")"; fi
  done
  if [ "$n" -ge 20 ]; then ok "$n peer shapes exported"; else bad "only $n peer shapes exported"; fi
  export_ok peer_loop_tess.glb "$SHAPES/loop_cube_creases0.obj" --tess 8
  export_ok peer_car_tess_uv.glb "$SHAPES/catmark_car.obj" --tess 2
  export_ok peer_pn.glb "$SHAPES/loop_icosahedron.obj" --scheme pn
  export_ok peer_car_flat.glb "$SHAPES/catmark_car.obj" --level 1 --normals flat
  export_ok peer_pole_limit.glb "$SHAPES/catmark_pole8.obj" --normals limit
else
  S=$((S + 1)); echo "SKIP peer shapes: not found at $SHAPES"
fi
# the real meshes (made by other people), as they are and with --crease-angle 30
if [ -d "$REAL" ] && ls "$REAL"/*.obj > /dev/null 2>&1; then
  for f in "$REAL"/*.obj; do
    b=$(basename "$f" .obj)
    export_ok "real_$b.glb" "$f" --level 1
    export_ok "real_${b}_angle.glb" "$f" --level 1 --crease-angle 30
    export_ok "real_${b}_tess.glb" "$f" --tess 3 --crease-angle 30
  done
else
  S=$((S + 1)); echo "SKIP real meshes: not found at $REAL"
fi

# ---- --fillet: seed 002's rolling-ball fillets (sfb_mesh_fillet) before the export ----
# a 90-degree fold: a 16 x 8 grid of squares (two triangles each) bent along its middle line, one
# open convex feature of 9 vertices whose dihedral angle is 90 degrees
awk -v N=8 -v M=8 'BEGIN {
  for (j = 0; j <= M; j++) for (i = -N; i <= N; i++) { x = i / N; z = 2 * j / M; if (x <= 0) printf "v %g 0 %g\n", x, z; else printf "v 0 %g %g\n", x, z }
  W = 2 * N + 1
  for (j = 0; j < M; j++) for (i = 0; i < 2 * N; i++) { a = j * W + i + 1; b = a + 1; c = a + W + 1; d = a + W; printf "f %d %d %d\nf %d %d %d\n", a, b, c, a, c, d }
}' > "$TMP/fold.obj"
FOLD=$TMP/fold.obj
FOLD_TRIS=$(grep -c '^f ' "$FOLD")
# the summary line's counts: "..., V vertices, T triangles -> ..."
tris() { sed -nE 's/.* ([0-9]+) vertices, ([0-9]+) triangles.*/\2/p' "$1" | tail -n 1; }
verts() { sed -nE 's/.* ([0-9]+) vertices, ([0-9]+) triangles.*/\1/p' "$1" | tail -n 1; }
rm -f "$TMP/fx.glb"
check "--fillet -1 is a usage error" 2 "$TOOL" --fillet -1 "$FOLD" -o "$TMP/fx.glb"
contains "--fillet -1: the message names the option" "$TMP/err" "--fillet needs a radius"
check "--fillet 0 is a usage error" 2 "$TOOL" --fillet 0 "$FOLD" -o "$TMP/fx.glb"
check "--fillet nan is a usage error" 2 "$TOOL" --fillet nan "$FOLD" -o "$TMP/fx.glb"
check "--fillet inf is a usage error" 2 "$TOOL" --fillet inf "$FOLD" -o "$TMP/fx.glb"
check "--fillet x is a usage error" 2 "$TOOL" --fillet x "$FOLD" -o "$TMP/fx.glb"
check "--fillet 1e-50 (0 as the library's float) is a usage error" 2 "$TOOL" --fillet 1e-50 "$FOLD" -o "$TMP/fx.glb"
check "--fillet 1e39 (infinite as a float) is a usage error" 2 "$TOOL" --fillet 1e39 "$FOLD" -o "$TMP/fx.glb"
check "--fillet without its radius is a usage error" 2 "$TOOL" "$FOLD" -o "$TMP/fx.glb" --fillet
# the fillet's features are the edges over --crease-angle: 0 and 180 would fillet at the
# library's default 30 degrees instead of the angle asked for
check "--fillet with --crease-angle 0 is a usage error" 2 "$TOOL" --fillet 0.3 --crease-angle 0 "$FOLD" -o "$TMP/fx.glb"
contains "--fillet --crease-angle 0: the message names the angle" "$TMP/err" "crease-angle"
check "--fillet with --crease-angle 180 is a usage error" 2 "$TOOL" --fillet 0.3 --crease-angle 180 "$FOLD" -o "$TMP/fx.glb"
absent "refused --fillet options leave no output" "$TMP/fx.glb"
# bad input: exit 1, one line, no output
badcase "--fillet on quads" "triangle mesh" "$BOX" --fillet 0.1
badcase "--fillet where no edge is over --crease-angle" "exceeds 91 degrees" "$FOLD" --fillet 0.3 --crease-angle 91
badcase "--fillet with a radius too large for the base patches" "too large" "$FOLD" --fillet 50
badcase "--fillet with --scheme loop on quads" "triangle mesh" "$BOX" --fillet 0.1 --scheme loop
if [ -e "$REAL/teapot.obj" ] && [ -e "$REAL/suzanne.obj" ]; then
  badcase "--fillet on the teapot (non-manifold vertices)" "non-manifold" "$REAL/teapot.obj" --fillet 0.05 --crease-angle 60
  badcase "--fillet on suzanne (quads and triangles)" "triangle mesh" "$REAL/suzanne.obj" --fillet 0.05
else
  S=$((S + 1)); echo "SKIP --fillet on the real meshes' refusals: not found at $REAL"
fi
# exports (all validated below): the same triangles, the feature rounded
check "export --fillet 0.3 --level 0" 0 "$TOOL" --level 0 --fillet 0.3 "$FOLD" -o "$TMP/v/fold_fillet_l0.glb"
contains "--fillet reports the curve and the radius" "$TMP/err" "1 curves filleted at radius 0.3"
t=$(tris "$TMP/err")
if [ "$t" = "$FOLD_TRIS" ]; then ok "--fillet --level 0 keeps the input's $FOLD_TRIS triangles"; else bad "--fillet --level 0 wrote '$t' triangles, the input has $FOLD_TRIS"; fi
check "export the fold --level 0 without --fillet" 0 "$TOOL" -q --level 0 "$FOLD" -o "$TMP/v/fold_l0.glb"
if [ -f "$TMP/v/fold_l0.glb" ] && [ -f "$TMP/v/fold_fillet_l0.glb" ] && ! cmp -s "$TMP/v/fold_l0.glb" "$TMP/v/fold_fillet_l0.glb"; then ok "--fillet moves vertices"
else bad "--fillet wrote the same file as without it"; fi
check "export --fillet -q" 0 "$TOOL" -q --fillet 0.3 "$FOLD" -o "$TMP/v/fold_fillet.glb"
if [ ! -s "$TMP/err" ]; then ok "--fillet -q prints nothing"; else bad "--fillet -q printed: $(head -n 1 "$TMP/err")"; fi
# --crease-angle is the fillet's feature angle: the 90-degree fold is a feature at 89, not at 91
# (above), and the crease that --crease-angle put on the filleted edge is dropped (no split)
check "export --fillet --crease-angle 89 --level 2" 0 "$TOOL" --level 2 --fillet 0.3 --crease-angle 89 "$FOLD" -o "$TMP/v/fold_fillet_a89.glb"
contains "--crease-angle 89: the fold is filleted" "$TMP/err" "1 curves filleted"
t=$(tris "$TMP/err"); v=$(verts "$TMP/err")
check "export --crease-angle 89 --level 2 without --fillet" 0 "$TOOL" --level 2 --crease-angle 89 "$FOLD" -o "$TMP/v/fold_a89.glb"
t0=$(tris "$TMP/err"); v0=$(verts "$TMP/err")
if [ -n "$t" ] && [ "$t" = "$t0" ]; then ok "--fillet keeps the refined triangle count ($t)"; else bad "--fillet --level 2: '$t' triangles, '$t0' without"; fi
if [ -n "$v" ] && [ -n "$v0" ] && [ "$v" -lt "$v0" ]; then ok "--fillet drops the filleted edge's crease ($v vertices, $v0 split along the crease)"
else bad "--fillet --crease-angle: '$v' vertices, '$v0' without (the filleted crease should no longer split them)"; fi
export_ok fold_fillet_qc.glb "$FOLD" --fillet 0.3 --crease-angle 45 --quantize --compress
export_ok fold_fillet.gltf "$FOLD" --fillet 0.3 --gltf
export_ok fold_fillet_tess.glb "$FOLD" --fillet 0.3 --crease-angle 45 --tess 6
export_ok fold_fillet_loop.glb "$FOLD" --fillet 0.3 --scheme loop --level 2
export_ok fold_fillet_lods.glb "$FOLD" --fillet 0.5 --lods 0,2
# glTF input: the fold as flat-shaded glTF (its fold edge a hard edge, i.e. an infinite crease)
check "the fold as flat-shaded glTF" 0 "$TOOL" -q --level 0 --normals flat "$FOLD" -o "$TMP/foldflat.glb"
check "export --fillet from glTF input" 0 "$TOOL" --level 1 --fillet 0.3 "$TMP/foldflat.glb" -o "$TMP/v/fold_fillet_from_gltf.glb"
contains "--fillet on glTF input names the primitive" "$TMP/err" "primitive 0: 1 curves filleted"
# a real triangle mesh with UVs (spot) and --crease-angle: the same triangles, validator-clean
if [ -e "$REAL/spot.obj" ]; then
  SPOT_TRIS=$(grep -c '^f ' "$REAL/spot.obj")
  check "export spot --fillet 0.02 --crease-angle 60 --level 0" 0 "$TOOL" --level 0 --fillet 0.02 --crease-angle 60 "$REAL/spot.obj" -o "$TMP/v/real_spot_fillet_l0.glb"
  contains "spot --fillet: three curves over 60 degrees" "$TMP/err" "3 curves filleted at radius 0.02"
  t=$(tris "$TMP/err")
  if [ "$t" = "$SPOT_TRIS" ]; then ok "spot --fillet --level 0 keeps its $SPOT_TRIS triangles"; else bad "spot --fillet --level 0 wrote '$t' triangles, the input has $SPOT_TRIS"; fi
  contains "spot --fillet keeps the UVs" "$TMP/err" "UVs"
  export_ok real_spot_fillet.glb "$REAL/spot.obj" --level 1 --fillet 0.02 --crease-angle 60
  export_ok real_spot_fillet_qc.glb "$REAL/spot.obj" --level 1 --fillet 0.05 --crease-angle 60 --quantize --compress
else
  S=$((S + 1)); echo "SKIP --fillet on spot: not found at $REAL"
fi

# ---- glTF input ----
printf 'v -1 -1 1\nv 1 -1 1\nv -1 1 1\nv 1 1 1\nv -1 1 -1\nv 1 1 -1\nv -1 -1 -1\nv 1 -1 -1\nf 1 2 4 3\nf 3 4 6 5\nf 5 6 8 7\nf 7 8 2 1\nf 2 8 6 4\nf 7 1 3 5\n' > "$TMP/qcube.obj"
# the same cube as triangles (each quad fanned from its first corner), plain and with its 12
# edges infinitely sharp: what a flat-shaded glTF cube is
awk '/^v /{print} /^f /{print "f", $2, $3, $4; print "f", $2, $4, $5}' "$TMP/qcube.obj" > "$TMP/tcube.obj"
cp "$TMP/tcube.obj" "$TMP/tcube_hard.obj"
for e in "1 2" "2 4" "4 3" "3 1" "3 5" "4 6" "5 6" "5 7" "6 8" "7 8" "8 2" "7 1"; do
  set -- $e; echo "t crease 2/1/0 $(($1 - 1)) $(($2 - 1)) 10" >> "$TMP/tcube_hard.obj"
done
# a flat-shaded cube written by sfb2gltf itself (level 0: the control mesh, split per face)
check "a flat-shaded glTF cube" 0 "$TOOL" -q --level 0 --normals flat "$TMP/qcube.obj" -o "$TMP/flatcube.glb"
check "glTF input: the flat cube subdivided" 0 "$TOOL" -q --backend ref --level 2 "$TMP/flatcube.glb" -o "$TMP/v/in_flatcube.glb"
count_check "$TMP/v/in_flatcube.glb" "$TMP/tcube_hard.obj" --level 2 --min-splits 20
check "glTF input: the flat cube as .gltf" 0 "$TOOL" -q --level 0 --normals flat --gltf "$TMP/qcube.obj" -o "$TMP/flatcube.gltf"
check "glTF input from .gltf + .bin" 0 "$TOOL" -q --backend ref --level 2 "$TMP/flatcube.gltf" -o "$TMP/v/in_flatcube_gltf.glb"
count_check "$TMP/v/in_flatcube_gltf.glb" "$TMP/tcube_hard.obj" --level 2 --min-splits 20
check "glTF input --crease-angle" 0 "$TOOL" -q --backend ref --level 2 --crease-angle 30 "$TMP/flatcube.glb" -o "$TMP/v/in_angle.glb"
count_check "$TMP/v/in_angle.glb" "$TMP/tcube_hard.obj" --level 2 --min-splits 20
# glTF written by another writer (tests/web/gltf_fixtures.mjs: no normals, so no hard edges),
# plain and quantized (KHR_mesh_quantization: positions as normalized SHORT, a node transform)
if node tests/web/gltf_fixtures.mjs --obj "$TMP/qcube.obj" "$TMP/fix.glb" > /dev/null 2>&1 &&
   node tests/web/gltf_fixtures.mjs --obj "$TMP/qcube.obj" "$TMP/fixq.glb" --quantize > /dev/null 2>&1; then
  check "glTF input from another writer" 0 "$TOOL" -q --backend ref --level 2 "$TMP/fix.glb" -o "$TMP/v/in_fix.glb"
  count_check "$TMP/v/in_fix.glb" "$TMP/tcube.obj" --level 2
  check "quantized glTF input" 0 "$TOOL" -q --level 2 --gltf "$TMP/fixq.glb" -o "$TMP/v/in_fixq.gltf"
  contains "the input's node transform is kept" "$TMP/v/in_fixq.gltf" '"scale"'
else
  S=$((S + 1)); echo "SKIP glTF input from tests/web/gltf_fixtures.mjs: node did not run"
fi
# two meshes, two nodes with transforms, a material: kept
b64() { base64 -w 0; }
f0='\x00\x00\x00\x00'; f1='\x00\x00\x80\x3f' # 0.0f, 1.0f (little-endian)
u() { printf '\\x%02x\\x00' "$@"; } # uint16 indices
TETRA=$(printf "$f0$f0$f0$f1$f0$f0$f0$f1$f0$f0$f0$f1$(u 0 2 1 0 1 3 0 3 2 1 2 3)" | b64)
gltf_doc() { # primitive JSON (mode, attributes, indices) -> a one-buffer glTF on the tetrahedron's 72 bytes
  cat <<JSON
{"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0, 1]}],
 "nodes": [{"name": "left", "mesh": 0, "translation": [-2, 0, 0]}, {"name": "right", "mesh": 1, "translation": [2, 0, 0]}],
 "materials": [{"name": "red paint", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.1, 0.1, 1]}}],
 "meshes": [{"name": "tetra A", "primitives": [$1]}, {"name": "tetra B", "primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
 "buffers": [{"byteLength": 72, "uri": "data:application/octet-stream;base64,$TETRA"}],
 "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 24}],
 "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 1]},
               {"bufferView": 1, "componentType": 5123, "count": 12, "type": "SCALAR"}]${2:-}}
JSON
}
gltf_doc '{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}' > "$TMP/two.gltf"
check "glTF input with two meshes" 0 "$TOOL" --level 2 --gltf "$TMP/two.gltf" -o "$TMP/v/in_two.gltf"
contains "both meshes are read" "$TMP/err" "2 meshes"
contains "the nodes' transforms are kept" "$TMP/v/in_two.gltf" '"translation"'
contains "the node names are kept" "$TMP/v/in_two.gltf" '"right"'
contains "the mesh names are kept" "$TMP/v/in_two.gltf" '"tetra B"'
contains "the material is passed through" "$TMP/v/in_two.gltf" '"red paint"'
contains "the mesh without a material gets the default" "$TMP/v/in_two.gltf" '"surfblend default"'
check "glTF input with two meshes, two LODs" 0 "$TOOL" --lods 1,2 --gltf "$TMP/two.gltf" -o "$TMP/v/in_two_lods.gltf"
contains "two meshes at two LODs are four" "$TMP/err" "4 meshes"
contains "a LOD node under a named node" "$TMP/v/in_two_lods.gltf" '"right level 2"'
gltf_doc '{"attributes": {"POSITION": 0}, "indices": 1, "extras": {"sfb_creases": [0, 1, 10, 1, 2, 2.5]}}' > "$TMP/extras.gltf"
check "creases from extras.sfb_creases" 0 "$TOOL" -q --level 1 "$TMP/extras.gltf" -o "$TMP/v/in_extras.glb"
# bad glTF input: the message names the file and the problem, no output
gltf_doc '{"attributes": {"POSITION": 0}, "indices": 1, "mode": 0}' > "$TMP/points.gltf"
badcase "a POINTS primitive" "mode 0" "$TMP/points.gltf"
gltf_doc '{"attributes": {"NORMAL": 0}, "indices": 1}' > "$TMP/nopos.gltf"
badcase "a primitive without POSITION" "POSITION" "$TMP/nopos.gltf"
gltf_doc '{"attributes": {"POSITION": 0}, "indices": 1, "extras": {"sfb_creases": [0, 9, 10]}}' > "$TMP/badextras.gltf"
badcase "extras.sfb_creases out of range" "sfb_creases" "$TMP/badextras.gltf"
sed 's/"count": 4, "type": "VEC3", "min": \[0, 0, 0\], "max": \[1, 1, 1\]}/"count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 1], "sparse": {"count": 1, "indices": {"bufferView": 1, "componentType": 5123}, "values": {"bufferView": 0}}}/' "$TMP/two.gltf" > "$TMP/sparse.gltf"
badcase "a sparse accessor" "sparse" "$TMP/sparse.gltf"
sed 's/"count": 4, "type": "VEC3"/"count": 3, "type": "VEC3"/' "$TMP/two.gltf" > "$TMP/oob.gltf"
badcase "an index out of range" "out of range" "$TMP/oob.gltf"
printf 'glTF\x02\x00\x00\x00junk' > "$TMP/junk.glb"
badcase "a broken .glb" "not a readable glTF" "$TMP/junk.glb"
printf '{"asset": {"version": "2.0"}}' > "$TMP/nomesh.gltf"
badcase "a glTF without meshes" "no triangles" "$TMP/nomesh.gltf"

# ---- the Khronos validator on every export ----
$VALIDATE "$TMP"/v/*.glb "$TMP"/v/*.gltf > "$TMP/val" 2>&1; rc=$?
if [ "$rc" = 0 ]; then
  ok "glTF-Validator: $(grep -c '^ok' "$TMP/val") files, 0 errors, 0 warnings"
elif [ "$rc" = 3 ] && [ -z "${SFB_REQUIRE_WEB:-}" ]; then
  S=$((S + 1)); echo "SKIP glTF-Validator: $(head -n 1 "$TMP/val") (make deps-web installs it)"
else
  bad "glTF-Validator (exit $rc) found errors or warnings, or did not run:"; grep -v '^ok' "$TMP/val" | head -n 20
fi

# ---- read back against the library (ref backend on both sides: the same numbers) ----
mkdir -p "$TMP/r"
readback() { # name, input, options for both..., -- checker-only options
  local name=$1 in=$2; shift 2
  [ -e "$in" ] || { S=$((S + 1)); echo "SKIP read back $name: $in is not here (the sanitizer run's reduced shape set)"; return; }
  local opts=() extra=()
  while [ $# -gt 0 ] && [ "$1" != -- ]; do opts+=("$1"); shift; done
  [ $# -gt 0 ] && shift
  extra=("$@")
  if "$TOOL" -q --backend ref "${opts[@]}" "$in" -o "$TMP/r/$name" 2> "$TMP/err"; then
    count_check "$TMP/r/$name" "$in" "${opts[@]}" "${extra[@]}"
  else
    bad "export $name for reading back: $(head -n 1 "$TMP/err")"
  fi
}
readback box.glb "$BOX" --level 3
readback box_limit.glb "$BOX" --level 2 --normals limit
readback box_flat.gltf "$BOX" --level 2 --normals flat
readback box_tess.glb "$BOX" --tess 6
readback box_quant.glb "$BOX" --level 3 --quantize
readback box_quant_bits.glb "$BOX" --level 2 --quantize --position-bits 10 --normal-bits 12
readback box_quant_tess.glb "$BOX" --tess 5 --quantize --position-bits 16 --normal-bits 16
readback box_compress.glb "$BOX" --level 3 --compress
readback box_compress_quant.gltf "$BOX" --level 2 --compress --quantize
# hard edges: a cube whose 12 edges are infinitely sharp (t crease), and the same by --crease-angle
printf 'v -1 -1 1\nv 1 -1 1\nv -1 1 1\nv 1 1 1\nv -1 1 -1\nv 1 1 -1\nv -1 -1 -1\nv 1 -1 -1\nf 1 2 4 3\nf 3 4 6 5\nf 5 6 8 7\nf 7 8 2 1\nf 2 8 6 4\nf 7 1 3 5\n' > "$TMP/cube.obj"
cp "$TMP/cube.obj" "$TMP/hard.obj"
for e in "1 2" "2 4" "4 3" "3 1" "3 5" "4 6" "5 6" "5 7" "6 8" "7 8" "8 2" "7 1"; do
  set -- $e; echo "t crease 2/1/0 $(($1 - 1)) $(($2 - 1)) 10" >> "$TMP/hard.obj"
done
readback hard.glb "$TMP/hard.obj" --level 2 -- --min-splits 20
readback hard_angle.glb "$TMP/cube.obj" --level 2 --crease-angle 30 -- --min-splits 20
readback hard_tess.glb "$TMP/hard.obj" --tess 4 -- --min-splits 20
if [ -d "$SHAPES" ]; then
  readback car.glb "$SHAPES/catmark_car.obj" --level 2 -- --uvs yes
  readback car_quant.glb "$SHAPES/catmark_car.obj" --level 2 --quantize --uv-bits 10 -- --uvs yes
  readback car_compress.glb "$SHAPES/catmark_car.obj" --level 2 --quantize --compress -- --uvs yes
  readback car_compress_uv10.glb "$SHAPES/catmark_car.obj" --level 1 --quantize --compress --uv-bits 10 -- --uvs yes
  readback fvar.glb "$SHAPES/catmark_fvar_bound1.obj" --level 2 -- --uvs yes
  readback loop.glb "$SHAPES/loop_cube_creases1.obj" --level 2
  readback loop_tess.glb "$SHAPES/loop_cube_creases1.obj" --tess 5
  readback holes.glb "$SHAPES/catmark_hole_test2.obj" --level 2
  readback nonman.glb "$SHAPES/catmark_nonman_edges.obj" --level 2
  readback bilinear.glb "$SHAPES/bilinear_nonquads0.obj" --level 1 -- --uvs yes
  readback manifold.glb "$SHAPES/catmark_cube_creases1.obj" --scheme manifold --tess 8
  # tessellated UVs (SFB_TESS_UVS): seams split, every vertex's UV the library's
  readback car_tess.glb "$SHAPES/catmark_car.obj" --tess 3 -- --uvs yes
  readback fvar_tess.glb "$SHAPES/catmark_fvar_bound1.obj" --tess 4 -- --uvs yes
  readback fvar_tess_quant.glb "$SHAPES/catmark_fvar_bound1.obj" --tess 4 --quantize --compress -- --uvs yes
  readback loop_tess_uv.glb "$SHAPES/loop_chaikin1.obj" --tess 4 -- --uvs yes
  readback manifold_uv.glb "$SHAPES/catmark_fvar_bound1.obj" --scheme manifold --tess 6 -- --uvs yes
  # PN triangles (evaluated only: tessellated like the manifold blend)
  readback pn.glb "$SHAPES/loop_icosahedron.obj" --scheme pn --tess 6
  readback pn_uv.glb "$SHAPES/loop_chaikin1.obj" --scheme pn --tess 4 -- --uvs yes
  readback noopt.glb "$SHAPES/catmark_chaikin1.obj" --level 2 --no-optimize
fi
# --fillet: the export is the library's surface of the mesh `surfblend fillet` writes (the same
# sfb_mesh_fillet call; the filleted edges carry no crease, with or without --crease-angle)
fillet_readback() { # name, the filleted OBJ, input, sfb2gltf options..., -- the checker's options
  local name=$1 ref=$2 in=$3; shift 3
  local opts=()
  while [ $# -gt 0 ] && [ "$1" != -- ]; do opts+=("$1"); shift; done
  [ $# -gt 0 ] && shift
  if "$TOOL" -q --backend ref "${opts[@]}" "$in" -o "$TMP/r/$name" 2> "$TMP/err"; then
    count_check "$TMP/r/$name" "$ref" "$@"
  else
    bad "export $name for reading back: $(head -n 1 "$TMP/err")"
  fi
}
if "$BUILD/surfblend" fillet --radius 0.3 "$FOLD" -o "$TMP/fold_filleted.obj" 2> "$TMP/err"; then
  fillet_readback fold_fillet.glb "$TMP/fold_filleted.obj" "$FOLD" --level 2 --fillet 0.3 -- --level 2
  fillet_readback fold_fillet_a45.glb "$TMP/fold_filleted.obj" "$FOLD" --level 2 --fillet 0.3 --crease-angle 45 -- --level 2
  fillet_readback fold_fillet_loop.glb "$TMP/fold_filleted.obj" "$FOLD" --scheme loop --level 2 --fillet 0.3 -- --scheme loop --level 2
  # and not the unfilleted fold's surface
  if "$CHECK" "$TMP/r/fold_fillet.glb" "$FOLD" --level 2 2>&1 | grep -q '^FAIL.*every vertex is the library'; then ok "the filleted export is not the unfilleted surface"
  else bad "the filleted export reads back as the unfilleted fold's surface"; fi
else
  bad "surfblend fillet on the fold: $(head -n 1 "$TMP/err")"
fi
if [ -e "$REAL/spot.obj" ]; then
  if "$BUILD/surfblend" fillet --radius 0.02 --angle 60 "$REAL/spot.obj" -o "$TMP/spot_filleted.obj" 2> "$TMP/err"; then
    fillet_readback spot_fillet.glb "$TMP/spot_filleted.obj" "$REAL/spot.obj" --level 1 --fillet 0.02 --crease-angle 60 -- --level 1 --uvs yes
  else
    bad "surfblend fillet on spot: $(head -n 1 "$TMP/err")"
  fi
fi
# the default backend gives the same counts (the numbers within the backends' agreement)
if "$TOOL" -q "$BOX" -o "$TMP/r/default.glb" && "$TOOL" -q --backend ref "$BOX" -o "$TMP/r/ref.glb"; then
  a=$(stat -c %s "$TMP/r/default.glb"); b=$(stat -c %s "$TMP/r/ref.glb")
  if [ "$a" = "$b" ]; then ok "the default backend's export has the ref export's size ($a bytes)"; else bad "export sizes differ: default $a, ref $b"; fi
else
  bad "exports on the default and ref backends"
fi

echo "$P passed, $F failed, $S skipped"
[ "$F" = 0 ]
