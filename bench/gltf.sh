#!/bin/bash
# make bench's gltf section: sfb2gltf's whole export (read -> build -> evaluate -> optimise ->
# write), plain and with --quantize --compress, beside gltfpack (npm, make deps-web) repacking our
# plain .glb with -cc (its default drops the unused TEXCOORD_0; -kv keeps it, the same content as
# ours). Times are the best of RUNS runs on this machine; sizes in bytes.
# Targets (issue 15): our compressed size <= 1.05 x gltfpack's; our whole export faster than
# gltfpack's repacking alone; the plain export of >= 1 M triangles <= 1 s.
set -u
BUILD=${BUILD:-build}
SHAPES=${SHAPES:-../shared/peers/opensubdiv-shapes}
RUNS=${RUNS:-3}
TOOL=$BUILD/sfb2gltf
GLTFPACK=${GLTFPACK:-$BUILD/node/node_modules/.bin/gltfpack}
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
[ -x "$TOOL" ] || { echo "gltf: $TOOL not built"; exit 1; }
[ -f "$SHAPES/catmark_car.obj" ] || { echo "gltf: skipped (peer shapes not found at $SHAPES)"; exit 0; }
have_pack=1; [ -x "$GLTFPACK" ] || { have_pack=0; echo "gltf: gltfpack not found at $GLTFPACK (make deps-web): its columns are empty"; }

# best wall time of RUNS runs of a command, in seconds
best() {
  local b="" t0 t1 d i
  for i in $(seq "$RUNS"); do
    t0=$(date +%s.%N); "$@" > /dev/null 2>&1 || { echo fail; return; }; t1=$(date +%s.%N)
    d=$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.3f", b - a }')
    if [ -z "$b" ] || awk -v d="$d" -v b="$b" 'BEGIN { exit !(d < b) }'; then b=$d; fi
  done
  echo "$b"
}
size() { stat -c %s "$1" 2>/dev/null || echo 0; }
ratio() { awk -v a="$1" -v b="$2" 'BEGIN { if (b + 0 > 0 && a != "fail" && b != "fail") printf "%.2f", a / b; else printf "-" }'; }

printf '\n== gltf: sfb2gltf beside gltfpack -cc (best of %d runs; sizes in bytes)\n' "$RUNS"
printf '%-34s %10s %9s %10s %9s %10s %9s %10s %9s %7s %7s\n' case triangles "plain s" "plain B" "q+c s" "q+c B" "pack s" "pack B" "pack-kv" "B/pack" "s/pack"
row() { # name, options...
  local name=$1; shift
  local tp tc sp sc tg sg sk tri
  tp=$(best "$TOOL" -q "$@" "$SHAPES/catmark_car.obj" -o "$TMP/plain.glb"); sp=$(size "$TMP/plain.glb")
  tc=$(best "$TOOL" -q --quantize --compress "$@" "$SHAPES/catmark_car.obj" -o "$TMP/qc.glb"); sc=$(size "$TMP/qc.glb")
  tri=$("$TOOL" "$@" "$SHAPES/catmark_car.obj" -o "$TMP/plain.glb" 2>&1 | sed -nE 's/.* ([0-9]+) triangles.*/\1/p')
  tg=-; sg=-; sk=-
  if [ "$have_pack" = 1 ]; then
    tg=$(best "$GLTFPACK" -i "$TMP/plain.glb" -o "$TMP/pack.glb" -cc); sg=$(size "$TMP/pack.glb")
    "$GLTFPACK" -i "$TMP/plain.glb" -o "$TMP/pack_kv.glb" -cc -kv > /dev/null 2>&1; sk=$(size "$TMP/pack_kv.glb")
  fi
  # B/pack: our compressed size over gltfpack -cc -kv's (the same attributes); s/pack: our whole
  # compressed export's time over gltfpack's repacking alone
  printf '%-34s %10s %9s %10s %9s %10s %9s %10s %9s %7s %7s\n' "$name" "$tri" "$tp" "$sp" "$tc" "$sc" "$tg" "$sg" "$sk" \
    "$(ratio "$sc" "$sk")" "$(ratio "$tc" "$tg")"
}
row "catmark_car --level 3" --level 3
row "catmark_car --tess 18 (exact limit)" --tess 18
echo "targets: B/pack <= 1.05, s/pack < 1, plain export of >= 1 M triangles <= 1 s"
