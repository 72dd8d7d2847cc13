#!/bin/bash
# Tests of the surfblend command-line tool: exit codes, messages, and that `refine` gives the
# same vertex count as OpenSubdiv's uniform refinement on every peer shape.
set -u
BUILD=${BUILD:-build}
SHAPES=${SHAPES:-../shared/peers/opensubdiv-shapes}
CLI=$BUILD/surfblend
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
P=0; F=0; S=0
check() { # description, expected exit code, command...
  local desc=$1 want=$2; shift 2
  "$@" > "$TMP/out" 2> "$TMP/err"; local got=$?
  if [ "$got" = "$want" ]; then P=$((P + 1)); echo "ok $desc"
  else F=$((F + 1)); echo "FAIL $desc: exit $got, wanted $want"; head -n 5 "$TMP/err"; fi
}
contains() { # description, file, pattern
  if grep -qi -- "$3" "$2"; then P=$((P + 1)); echo "ok $1"; else F=$((F + 1)); echo "FAIL $1: '$3' not in output"; head -n 5 "$2"; fi
}

check "no arguments is a usage error" 2 "$CLI"
check "--help succeeds" 0 "$CLI" --help
contains "--help shows refine" "$TMP/out" "refine"
contains "--help shows tess" "$TMP/out" "surfblend tess"
contains "--help shows eval" "$TMP/out" "surfblend eval"
check "unknown command is a usage error" 2 "$CLI" frobnicate
# usage: printed from the option table, on stdout with exit 0 when asked for
for h in -h help; do
  check "$h succeeds" 0 "$CLI" $h
  if [ -s "$TMP/out" ] && [ ! -s "$TMP/err" ]; then P=$((P + 1)); echo "ok $h prints on stdout only"; else F=$((F + 1)); echo "FAIL $h output: stdout/stderr"; fi
  contains "$h shows render" "$TMP/out" "surfblend render"
done
contains "--help names the option spelling" "$TMP/out" "--manifold-weights"
# each command's options (some of them) as its --help must show them
cmd_opts() { case $1 in
  info) echo "-h, --help" ;; backends) echo "-h, --help" ;;
  refine) echo "--scheme --level --limit --backend -o, --output" ;;
  eval) echo "--manifold-weights, --weights --locations --random --seed --derivatives --backend" ;;
  tess) echo "--manifold-weights, --weights --rate --tolerance --split-creases --trim --trim-tiles" ;;
  shade) echo "--variant --darts --normals-level --weights-level --p --averaging --all-subdivided --limit" ;;
  render) echo "--normals --highlight --blend-weights, --weights --normal-colors --positions --size --view --zoom --stripes --up --edges --rate --manifold-weights --trim" ;;
  analyze) echo "--mode --light --curvature --level --polygon-based --size --view --eye --target --up --fov --orthographic --stripes --band --backend" ;;
  fillet) echo "--radius --angle --profile --curve --samples --alpha --relax --skip-failed -o, --output" ;;
  esac; }
for c in info refine eval tess shade render analyze fillet backends; do
  check "$c --help succeeds" 0 "$CLI" $c --help
  if [ -s "$TMP/out" ] && [ ! -s "$TMP/err" ]; then P=$((P + 1)); echo "ok $c --help prints on stdout only"; else F=$((F + 1)); echo "FAIL $c --help: empty stdout or output on stderr"; fi
  contains "$c --help shows the command" "$TMP/out" "^  surfblend $c"
  if [ "$(grep -c '^  surfblend ' "$TMP/out")" = 1 ]; then P=$((P + 1)); echo "ok $c --help shows that command only"; else F=$((F + 1)); echo "FAIL $c --help shows other commands"; fi
  missing=""
  IFS=' ' read -r -a want <<< "$(cmd_opts $c | sed 's/, /,_/g')"
  for o in "${want[@]}"; do grep -q -- "^      ${o//,_/, }\( \|$\)" "$TMP/out" || missing="$missing ${o//,_/, }"; done
  if [ -z "$missing" ]; then P=$((P + 1)); echo "ok $c --help lists its options"; else F=$((F + 1)); echo "FAIL $c --help lacks:$missing"; fi
  cp "$TMP/out" "$TMP/help_$c"
  check "$c -h succeeds" 0 "$CLI" $c -h
  check "help $c succeeds" 0 "$CLI" help $c
  if cmp -s "$TMP/out" "$TMP/help_$c"; then P=$((P + 1)); echo "ok help $c is $c --help"; else F=$((F + 1)); echo "FAIL help $c differs from $c --help"; fi
  check "$c with an unknown option is a usage error" 2 "$CLI" $c --frobnicate examples/data/creased_box.obj -o "$TMP/x.out"
  contains "$c names the unknown option" "$TMP/err" "unknown option '--frobnicate'"
done
check "help of an unknown command is a usage error" 2 "$CLI" help frobnicate
check "tess --help after other options succeeds" 0 "$CLI" tess --rate 3 --help
contains "tess --help shows tess" "$TMP/out" "surfblend tess"
check "refine --weights (an option of other commands) is a usage error" 2 "$CLI" refine --weights cinf examples/data/creased_box.obj -o "$TMP/x.obj"
check "shade --blend-weights (render's) is a usage error" 2 "$CLI" shade --blend-weights examples/data/creased_box.obj -o "$TMP/x.obj"
check "refine without -o is a usage error" 2 "$CLI" refine examples/data/creased_box.obj
check "bad --level is a usage error" 2 "$CLI" refine --level x examples/data/creased_box.obj -o "$TMP/o.obj"
check "missing file is bad input" 1 "$CLI" info "$TMP/does-not-exist.obj"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n' > "$TMP/bad.obj"
check "out-of-range index is bad input" 1 "$CLI" info "$TMP/bad.obj"
contains "bad input message names the line" "$TMP/err" "line 4"
check "level over the limit is bad input" 1 "$CLI" refine --level 11 examples/data/creased_box.obj -o "$TMP/o.obj"
contains "level message names the limit" "$TMP/err" "limit"
check "loop on quads is bad input" 1 "$CLI" refine --scheme loop examples/data/creased_box.obj -o "$TMP/o.obj"
printf 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nf 1 2 3 4\nf 2 5 3\n' > "$TMP/mixed.obj"
check "info on a mixed mesh succeeds" 0 "$CLI" info "$TMP/mixed.obj"
contains "info names the faces that are not triangles" "$TMP/out" "mixed face sizes: 1 of 2 faces are not triangles (loop, tribezier and pn"
contains "info names --triangulate for them" "$TMP/out" "take triangles only: --triangulate"
check "info --triangulate on a mixed mesh succeeds" 0 "$CLI" info --triangulate "$TMP/mixed.obj"
contains "info --triangulate: 3 triangles, no problem" "$TMP/out" "problems: *none"
check "info succeeds" 0 "$CLI" info examples/data/creased_box.obj
contains "info shows the valence histogram" "$TMP/out" "valence histogram"
check "refine succeeds" 0 "$CLI" refine --level 2 examples/data/creased_box.obj -o "$TMP/o.obj"
check "refined output reads back" 0 "$CLI" info "$TMP/o.obj"
contains "refined output keeps semi-sharp creases" "$TMP/out" "semi-sharp"
check "refine --limit succeeds" 0 "$CLI" refine --limit --level 1 examples/data/creased_box.obj -o "$TMP/l.obj"
contains "limit output has normals" "$TMP/l.obj" "^vn "
check "--backend ref works" 0 "$CLI" refine --backend ref --level 1 examples/data/creased_box.obj -o "$TMP/o.obj"
check "--backend bogus is bad input" 1 "$CLI" refine --backend bogus --level 1 examples/data/creased_box.obj -o "$TMP/o.obj"
check "backends lists" 0 "$CLI" backends
contains "backends lists ref as available" "$TMP/out" "^ref *available"
for b in simd gl osmesa; do contains "backends lists $b" "$TMP/out" "^$b *\(available\|unavailable\)"; done
# where a backend is required (CI: SFB_REQUIRE_BACKENDS=simd,gl,osmesa) it must be available
for b in $(echo "${SFB_REQUIRE_BACKENDS:-}" | tr ',' ' '); do contains "required backend $b is available" "$TMP/out" "^$b *available"; done

# max |difference| between the vertex lines of two OBJ files, or "count" if they differ in number
objdiff() { paste -d' ' <(grep '^v ' "$1") <(grep '^v ' "$2") | awk 'NF != 8 { print "count"; exit }
  { for (i = 2; i <= 4; ++i) { d = $i - $(i + 4); if (d < 0) d = -d; if (d > m) m = d } } END { if (NR > 0 && m != "count") printf "%g\n", m + 0 }'; }
"$CLI" refine --backend ref --level 3 --limit examples/data/creased_box.obj -o "$TMP/ref.obj" 2>/dev/null
for b in simd gl osmesa; do
  if grep -q "^$b *available" "$TMP/out"; then
    check "refine --backend $b works" 0 "$CLI" refine --backend $b --level 3 --limit examples/data/creased_box.obj -o "$TMP/$b.obj"
    contains "refine --backend $b ran on $b" "$TMP/err" "(backend $b)"
    d=$(objdiff "$TMP/ref.obj" "$TMP/$b.obj")
    # 1e-5 x the box's diagonal (about 3.5) is the agreement tolerance; OBJ keeps 6-7 digits
    if [ "$d" != count ] && awk -v d="$d" 'BEGIN { exit !(d < 3.5e-5) }'; then P=$((P + 1)); echo "ok refine on $b agrees with ref ($d)"
    else F=$((F + 1)); echo "FAIL refine on $b differs from ref: $d"; fi
  fi
done
check "SURFBLEND_BACKEND=bogus falls back" 0 env SURFBLEND_BACKEND=bogus "$CLI" refine --level 1 examples/data/creased_box.obj -o "$TMP/o.obj"
contains "SURFBLEND_BACKEND=bogus is reported" "$TMP/err" "bogus: unavailable (unknown backend name"

# ---- tess and eval (limit surface through the patch table) ----
# "boundary non-manifold duplicated-directed" edge counts of the triangles of an OBJ's f lines
edge_stats() { awk '/^f /{ for (i = 2; i <= 4; ++i) { split($i, a, "/"); v[i - 1] = a[1] }
    for (i = 1; i <= 3; ++i) { p = v[i]; q = v[i % 3 + 1]; if (d[p " " q]++) dup++; k = (p + 0 < q + 0) ? p " " q : q " " p; u[k]++ } }
  END { b = 0; m = 0; for (k in u) { if (u[k] == 1) b++; else if (u[k] > 2) m++ } printf "%d %d %d\n", b, m, dup + 0 }' "$1"; }
printf 'v -1 -1 1\nv 1 -1 1\nv -1 1 1\nv 1 1 1\nv -1 1 -1\nv 1 1 -1\nv -1 -1 -1\nv 1 -1 -1\nf 1 2 4 3\nf 3 4 6 5\nf 5 6 8 7\nf 7 8 2 1\nf 2 8 6 4\nf 7 1 3 5\n' > "$TMP/cube.obj"
printf 'v 1 0 -1\nv 0.309017 0.951057 -1\nv -0.809017 0.587785 -1\nv -0.809017 -0.587785 -1\nv 0.309017 -0.951057 -1\nv 1 0 1\nv 0.309017 0.951057 1\nv -0.809017 0.587785 1\nv -0.809017 -0.587785 1\nv 0.309017 -0.951057 1\nf 6 7 8 9 10\nf 5 4 3 2 1\nf 1 2 7 6\nf 2 3 8 7\nf 3 4 9 8\nf 4 5 10 9\nf 5 1 6 10\n' > "$TMP/prism.obj"
# --crease-angle (shared with sfb2gltf): the cube's 12 edges are at 90 degrees
check "info --crease-angle 30 succeeds" 0 "$CLI" info --crease-angle 30 "$TMP/cube.obj"
contains "--crease-angle 30 makes the cube's edges sharp" "$TMP/out" "12 infinitely sharp"
check "info --crease-angle 120 succeeds" 0 "$CLI" info --crease-angle 120 "$TMP/cube.obj"
contains "--crease-angle 120 leaves them smooth" "$TMP/out" "0 infinitely sharp"
check "--crease-angle 0 is a usage error" 2 "$CLI" info --crease-angle 0 "$TMP/cube.obj"
check "--crease-angle 181 is a usage error" 2 "$CLI" refine --crease-angle 181 "$TMP/cube.obj" -o "$TMP/o.obj"
check "refine --crease-angle 30 succeeds" 0 "$CLI" refine --level 1 --crease-angle 30 "$TMP/cube.obj" -o "$TMP/o.obj"
check "its output reads back" 0 "$CLI" info "$TMP/o.obj"
contains "the refined cube keeps the sharp edges" "$TMP/out" "24 infinitely sharp"
for r in 1 2 5; do
  check "tess cube rate $r succeeds" 0 "$CLI" tess --rate $r "$TMP/cube.obj" -o "$TMP/t.obj"
  st=$(edge_stats "$TMP/t.obj")
  if [ "$st" = "0 0 0" ]; then P=$((P + 1)); echo "ok tess cube rate $r is closed"; else F=$((F + 1)); echo "FAIL tess cube rate $r is not closed: $st"; fi
  # V = nv + ne (r-1) + nf (r-1)^2 on a quad mesh
  got=$(grep -c '^v ' "$TMP/t.obj"); want=$((8 + 12 * (r - 1) + 6 * (r - 1) * (r - 1)))
  if [ "$got" = "$want" ]; then P=$((P + 1)); echo "ok tess cube rate $r has $want vertices"; else F=$((F + 1)); echo "FAIL tess cube rate $r: $got vertices, wanted $want"; fi
done
contains "tess prints a summary with edge counts" "$TMP/err" "closed, 0 boundary"
contains "tess writes normals" "$TMP/t.obj" "^vn "
contains "tess writes v//vn faces" "$TMP/t.obj" "^f [0-9]*//[0-9]* "
for shape in "$TMP/prism.obj" examples/data/creased_box.obj; do
  check "tess $(basename "$shape") succeeds" 0 "$CLI" tess --rate 3 "$shape" -o "$TMP/t.obj"
  st=$(edge_stats "$TMP/t.obj")
  if [ "$st" = "0 0 0" ]; then P=$((P + 1)); echo "ok tess $(basename "$shape") is closed"; else F=$((F + 1)); echo "FAIL tess $(basename "$shape") is not closed: $st"; fi
  check "adaptive tess $(basename "$shape") succeeds" 0 "$CLI" tess --rate 16 --tolerance 0.01 "$shape" -o "$TMP/t.obj"
  st=$(edge_stats "$TMP/t.obj")
  if [ "$st" = "0 0 0" ]; then P=$((P + 1)); echo "ok adaptive tess $(basename "$shape") is closed"; else F=$((F + 1)); echo "FAIL adaptive tess $(basename "$shape") is not closed: $st"; fi
done
# creased_box has one infinitely sharp edge: split, it opens into 2 x rate boundary edges
check "tess --split-creases succeeds" 0 "$CLI" tess --rate 3 --split-creases examples/data/creased_box.obj -o "$TMP/t.obj"
st=$(edge_stats "$TMP/t.obj")
if [ "$st" = "6 0 0" ]; then P=$((P + 1)); echo "ok split creases open only the sharp edge"; else F=$((F + 1)); echo "FAIL split creases: edge stats $st, wanted 6 0 0"; fi
check "tess --rate 0 is bad input" 1 "$CLI" tess --rate 0 "$TMP/cube.obj" -o "$TMP/t.obj"
contains "rate message names the range" "$TMP/err" "rate 0 is outside 1..1024"
check "tess --rate 1025 is bad input" 1 "$CLI" tess --rate 1025 "$TMP/cube.obj" -o "$TMP/t.obj"
check "tess negative tolerance is bad input" 1 "$CLI" tess --rate 4 --tolerance -1 "$TMP/cube.obj" -o "$TMP/t.obj"
check "tess without --rate is a usage error" 2 "$CLI" tess "$TMP/cube.obj" -o "$TMP/t.obj"
check "tess without -o is a usage error" 2 "$CLI" tess --rate 2 "$TMP/cube.obj"
check "tess --rate x is a usage error" 2 "$CLI" tess --rate x "$TMP/cube.obj" -o "$TMP/t.obj"

check "eval --random succeeds" 0 "$CLI" eval --random 25 --seed 3 examples/data/creased_box.obj
n=$(wc -l < "$TMP/out")
if [ "$n" = 25 ]; then P=$((P + 1)); echo "ok eval --random 25 prints 25 lines"; else F=$((F + 1)); echo "FAIL eval --random 25 printed $n lines"; fi
if awk 'NF != 9 { exit 1 }' "$TMP/out"; then P=$((P + 1)); echo "ok eval lines have 9 fields"; else F=$((F + 1)); echo "FAIL eval lines do not have 9 fields"; fi
cp "$TMP/out" "$TMP/r1"
check "eval --random -o succeeds" 0 "$CLI" eval --random 25 --seed 3 -o "$TMP/r2" examples/data/creased_box.obj
if cmp -s "$TMP/r1" "$TMP/r2"; then P=$((P + 1)); echo "ok eval --random is deterministic for a seed"; else F=$((F + 1)); echo "FAIL eval --random differs for the same seed"; fi
"$CLI" eval --random 25 --seed 4 examples/data/creased_box.obj > "$TMP/r3" 2>/dev/null
if ! cmp -s "$TMP/r1" "$TMP/r3"; then P=$((P + 1)); echo "ok eval --random depends on the seed"; else F=$((F + 1)); echo "FAIL eval --random ignores the seed"; fi
printf 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\nf 1 2 3 4\nf 2 5 6 3\nt hole 1/0/0 1\n' > "$TMP/holed.obj"
check "eval --random skips holes" 0 "$CLI" eval --random 40 "$TMP/holed.obj"
if awk '$1 != 0 { exit 1 }' "$TMP/out"; then P=$((P + 1)); echo "ok eval --random uses only the face that is not a hole"; else F=$((F + 1)); echo "FAIL eval --random sampled a hole"; fi
printf '# face u v\n0 0 0\n\n3 0.5 0.25  # a comment\n' > "$TMP/locs.txt"
check "eval --locations --derivatives succeeds" 0 "$CLI" eval --locations "$TMP/locs.txt" --derivatives "$TMP/cube.obj"
if [ "$(wc -l < "$TMP/out")" = 2 ] && awk 'NF != 15 { exit 1 }' "$TMP/out"; then P=$((P + 1)); echo "ok eval --derivatives prints 15 fields per location"
else F=$((F + 1)); echo "FAIL eval --derivatives output"; head -n 3 "$TMP/out"; fi
printf '0 0.5 0.5\n1 0.5\n' > "$TMP/badlocs.txt"
check "eval with a malformed location line is bad input" 1 "$CLI" eval --locations "$TMP/badlocs.txt" "$TMP/cube.obj"
contains "malformed location message names the line" "$TMP/err" "line 2"
printf '0 0.5 0.5\n# fine\n99 0.5 0.5\n' > "$TMP/badlocs.txt"
check "eval with a face out of range is bad input" 1 "$CLI" eval --locations "$TMP/badlocs.txt" "$TMP/cube.obj"
contains "out-of-range message names the line" "$TMP/err" "line 3"
contains "out-of-range message names the query" "$TMP/err" "location 1: parametric face 99 is out of range"
printf '0 1.5 0.5\n' > "$TMP/badlocs.txt"
check "eval with u outside [0,1] is bad input" 1 "$CLI" eval --locations "$TMP/badlocs.txt" "$TMP/cube.obj"
contains "u outside [0,1] is reported" "$TMP/err" "outside \[0,1\]"
check "eval without locations is a usage error" 2 "$CLI" eval "$TMP/cube.obj"
# Loop: triangles, barycentric (u,v) with u + v <= 1
printf 'v 1 1 1\nv -1 -1 1\nv -1 1 -1\nv 1 -1 -1\nf 1 2 3\nf 1 4 2\nf 1 3 4\nf 2 4 3\n' > "$TMP/tet.obj"
check "eval --scheme loop --random succeeds" 0 "$CLI" eval --scheme loop --random 200 --seed 5 "$TMP/tet.obj"
if awk 'NF != 9 || $1 < 0 || $1 > 3 || $2 < 0 || $3 < 0 || $2 + $3 > 1 { exit 1 }' "$TMP/out"; then P=$((P + 1)); echo "ok eval --scheme loop samples the triangles (u + v <= 1)"
else F=$((F + 1)); echo "FAIL eval --scheme loop sampled outside the triangles"; head -n 3 "$TMP/out"; fi
printf '0 0.25 0.25\n1 0.75 0.5\n' > "$TMP/badlocs.txt"
check "eval --scheme loop with u + v > 1 is bad input" 1 "$CLI" eval --scheme loop --locations "$TMP/badlocs.txt" "$TMP/tet.obj"
contains "u + v > 1 is reported with its query" "$TMP/err" "location 1: .* outside the triangle u + v <= 1"
check "eval --scheme loop on quads is bad input" 1 "$CLI" eval --scheme loop --random 3 "$TMP/cube.obj"
contains "Loop on quads is reported" "$TMP/err" "Loop subdivision needs triangles"
# --triangulate (sfb_mesh_triangulate): quads made triangles first, for the triangle schemes
check "eval --scheme loop --triangulate on quads succeeds" 0 "$CLI" eval --scheme loop --triangulate --random 20 "$TMP/cube.obj"
if awk 'NF != 9 || $1 < 0 || $1 > 11 { exit 1 } END { exit NR != 20 }' "$TMP/out"; then P=$((P + 1)); echo "ok eval --triangulate samples the cube's 12 triangles"
else F=$((F + 1)); echo "FAIL eval --triangulate: not 20 samples on faces 0..11"; head -n 3 "$TMP/out"; fi
for sch in tribezier pn; do
  check "tess --scheme $sch on quads is bad input" 1 "$CLI" tess --scheme $sch --rate 2 "$TMP/cube.obj" -o "$TMP/tq.obj"
  contains "tess --scheme $sch on quads names the option" "$TMP/err" "needs triangles.*--triangulate"
  check "tess --scheme $sch --triangulate on quads succeeds" 0 "$CLI" tess --scheme $sch --rate 2 --triangulate "$TMP/cube.obj" -o "$TMP/tq.obj"
  st=$(edge_stats "$TMP/tq.obj")
  if [ "$st" = "0 0 0" ]; then P=$((P + 1)); echo "ok tess $sch --triangulate cube is closed"; else F=$((F + 1)); echo "FAIL tess $sch --triangulate cube is not closed: $st"; fi
done
check "info --triangulate succeeds" 0 "$CLI" info --triangulate "$TMP/cube.obj"
contains "info --triangulate counts 12 triangles" "$TMP/out" "faces: *12 (12 triangles, 0 quads"
check "info on quads succeeds" 0 "$CLI" info "$TMP/cube.obj"
check "fillet --triangulate on quads succeeds" 0 "$CLI" fillet --triangulate --angle 60 --radius 0.2 "$TMP/cube.obj" -o "$TMP/cf.obj"
check "fillet on quads is bad input" 1 "$CLI" fillet --angle 60 --radius 0.2 "$TMP/cube.obj" -o "$TMP/cf2.obj"
contains "fillet on quads names the option" "$TMP/err" "--triangulate"
check "eval --scheme bilinear is bad input" 1 "$CLI" eval --scheme bilinear --random 3 "$TMP/cube.obj"
contains "bilinear limit evaluation is reported unsupported" "$TMP/err" "not supported"
for r in 1 4; do
  check "tess --scheme loop tetrahedron rate $r succeeds" 0 "$CLI" tess --scheme loop --rate $r "$TMP/tet.obj" -o "$TMP/t.obj"
  st=$(edge_stats "$TMP/t.obj")
  if [ "$st" = "0 0 0" ]; then P=$((P + 1)); echo "ok tess loop tetrahedron rate $r is closed"; else F=$((F + 1)); echo "FAIL tess loop tetrahedron rate $r is not closed: $st"; fi
  # a triangular grid of rate r: 4 r^2 triangles, V = 4 + 6 (r-1) + 4 (r-1)(r-2)/2
  got=$(grep -c '^f ' "$TMP/t.obj"); want=$((4 * r * r))
  if [ "$got" = "$want" ]; then P=$((P + 1)); echo "ok tess loop tetrahedron rate $r has $want triangles"; else F=$((F + 1)); echo "FAIL tess loop tetrahedron rate $r: $got triangles, wanted $want"; fi
  got=$(grep -c '^v ' "$TMP/t.obj"); want=$((4 + 6 * (r - 1) + 2 * (r - 1) * (r - 2)))
  if [ "$got" = "$want" ]; then P=$((P + 1)); echo "ok tess loop tetrahedron rate $r has $want vertices"; else F=$((F + 1)); echo "FAIL tess loop tetrahedron rate $r: $got vertices, wanted $want"; fi
done
check "eval with a missing location file is bad input" 1 "$CLI" eval --locations "$TMP/none.txt" "$TMP/cube.obj"
"$CLI" backends > "$TMP/backends" 2>/dev/null
"$CLI" tess --backend ref --rate 6 --split-creases examples/data/creased_box.obj -o "$TMP/tref.obj" 2>/dev/null
for b in simd gl osmesa; do
  if grep -q "^$b *available" "$TMP/backends"; then
    check "tess --backend $b works" 0 "$CLI" tess --backend $b --rate 6 --split-creases examples/data/creased_box.obj -o "$TMP/t$b.obj"
    d=$(objdiff "$TMP/tref.obj" "$TMP/t$b.obj")
    if [ "$d" != count ] && awk -v d="$d" 'BEGIN { exit !(d < 3.5e-5) }'; then P=$((P + 1)); echo "ok tess on $b agrees with ref ($d)"
    else F=$((F + 1)); echo "FAIL tess on $b differs from ref: $d"; fi
  fi
done

# ---- tess --trim: trimming masks from PNG pictures (written here with python3's zlib) ----
# mkpng OUT W H MODE: 8-bit grey, black where MODE says: left (left half), top / bottom (that half
# of the picture); rgb-left: the left-half picture as RGB
mkpng() { python3 - "$@" <<'PY'
import struct, sys, zlib
out, w, h, mode = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
def black(x, y):
    return {'left': x < w // 2, 'rgb-left': x < w // 2, 'top': y < h // 2, 'bottom': y >= h // 2}[mode]
rgb = mode.startswith('rgb')
raw = b''.join(b'\0' + b''.join(bytes([0 if black(x, y) else 255] * (3 if rgb else 1)) for x in range(w)) for y in range(h))
def chunk(t, d): return struct.pack('>I', len(d)) + t + d + struct.pack('>I', zlib.crc32(t + d) & 0xffffffff)
open(out, 'wb').write(b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', w, h, 8, 2 if rgb else 0, 0, 0, 0)) +
                      chunk(b'IDAT', zlib.compress(raw)) + chunk(b'IEND', b''))
PY
}
if command -v python3 > /dev/null 2>&1 && mkpng "$TMP/left.png" 16 16 left; then
  mkpng "$TMP/top.png" 16 16 top; mkpng "$TMP/bottom.png" 16 16 bottom; mkpng "$TMP/rgbleft.png" 16 16 rgb-left
  check "tess --trim succeeds" 0 "$CLI" tess --rate 2 --trim "$TMP/left.png" "$TMP/cube.obj" -o "$TMP/tt.obj"
  contains "tess --trim says it trimmed" "$TMP/err" "trimmed (16x16 mask)"
  # the contour u = 1/2 of the 16-texel mask: each face at rate 16 (raised from 2) keeps 16 x 8 cells
  got=$(grep -c '^f ' "$TMP/tt.obj")
  if [ "$got" = 1536 ]; then P=$((P + 1)); echo "ok tess --trim keeps half of each face (1536 triangles)"; else F=$((F + 1)); echo "FAIL tess --trim: $got triangles, wanted 1536"; fi
  st=$(edge_stats "$TMP/tt.obj")
  case "$st" in "0 "*|*" "[1-9]*" "*|*" "*" "[1-9]*) F=$((F + 1)); echo "FAIL tess --trim edges: $st (boundary non-manifold duplicated)";;
    *) P=$((P + 1)); echo "ok tess --trim has boundary edges, none non-manifold or repeated ($st)";; esac
  check "tess --trim with an RGB picture succeeds" 0 "$CLI" tess --rate 2 --trim "$TMP/rgbleft.png" "$TMP/cube.obj" -o "$TMP/ttc.obj"
  if cmp -s <(grep -v '^#' "$TMP/tt.obj") <(grep -v '^#' "$TMP/ttc.obj"); then P=$((P + 1)); echo "ok an RGB mask is read as its grey level"
  else F=$((F + 1)); echo "FAIL an RGB mask gives another tessellation than the grey one"; fi
  # a planar 3 x 3 grid: the middle face is the square [1,2]^2 with u along x, v along y
  printf 'v 0 0 0\nv 1 0 0\nv 2 0 0\nv 3 0 0\nv 0 1 0\nv 1 1 0\nv 2 1 0\nv 3 1 0\nv 0 2 0\nv 1 2 0\nv 2 2 0\nv 3 2 0\nv 0 3 0\nv 1 3 0\nv 2 3 0\nv 3 3 0\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 5 6 10 9\nf 6 7 11 10\nf 7 8 12 11\nf 9 10 14 13\nf 10 11 15 14\nf 11 12 16 15\n' > "$TMP/grid3.obj"
  # vertices strictly inside the upper (v > 1/2) and lower (v < 1/2) halves of the middle face
  halves() { awk '/^v / && $2 > 1.05 && $2 < 1.95 { if ($3 > 1.55 && $3 < 1.95) up++; if ($3 > 1.05 && $3 < 1.45) lo++ } END { printf "%d %d\n", up, lo }' "$1"; }
  check "tess --trim (picture's top half black) succeeds" 0 "$CLI" tess --rate 4 --trim "$TMP/top.png" "$TMP/grid3.obj" -o "$TMP/ttop.obj"
  check "tess --trim (picture's bottom half black) succeeds" 0 "$CLI" tess --rate 4 --trim "$TMP/bottom.png" "$TMP/grid3.obj" -o "$TMP/tbot.obj"
  ht=$(halves "$TMP/ttop.obj"); hb=$(halves "$TMP/tbot.obj")
  if [ "${ht%% *}" = 0 ] && [ "${ht##* }" -gt 0 ] && [ "${hb##* }" = 0 ] && [ "${hb%% *}" -gt 0 ]; then
    P=$((P + 1)); echo "ok the picture's top row is v = 1 (top black keeps v < 1/2: $ht; bottom black keeps v > 1/2: $hb)"
  else F=$((F + 1)); echo "FAIL mask rows are not flipped: top black leaves '$ht', bottom black '$hb' (upper lower)"; fi
  # a 2 x 2 atlas of the left-half picture: tiles 0 and 2 black, 1 and 3 white, faces 4 and 5 past the last tile
  check "tess --trim-tiles 2 2 succeeds" 0 "$CLI" tess --rate 2 --trim "$TMP/left.png" --trim-tiles 2 2 "$TMP/cube.obj" -o "$TMP/tta.obj"
  got=$(grep -c '^f ' "$TMP/tta.obj")
  if [ "$got" = 32 ]; then P=$((P + 1)); echo "ok --trim-tiles: faces 0 and 2 dropped, 1 3 4 5 whole (32 triangles)"; else F=$((F + 1)); echo "FAIL --trim-tiles 2 2: $got triangles, wanted 32"; fi
  check "tess --trim of a missing file is bad input" 1 "$CLI" tess --rate 2 --trim "$TMP/none.png" "$TMP/cube.obj" -o "$TMP/x.obj"
  contains "a missing mask is named" "$TMP/err" "cannot read the trimming mask"
  check "tess --trim of a file that is not a PNG is bad input" 1 "$CLI" tess --rate 2 --trim "$TMP/cube.obj" "$TMP/cube.obj" -o "$TMP/x.obj"
  contains "a bad mask file is named" "$TMP/err" "cannot read the trimming mask .*cube.obj"
  check "tess --trim-tiles 3 3 on 16 texels is bad input" 1 "$CLI" tess --rate 2 --trim "$TMP/left.png" --trim-tiles 3 3 "$TMP/cube.obj" -o "$TMP/x.obj"
  contains "uneven tiles are reported" "$TMP/err" "do not split into 3 x 3 equal tiles"
  check "tess --trim-tiles 2 0 is bad input" 1 "$CLI" tess --rate 2 --trim "$TMP/left.png" --trim-tiles 2 0 "$TMP/cube.obj" -o "$TMP/x.obj"
  check "tess --trim-tiles with one number is a usage error" 2 "$CLI" tess --rate 2 --trim "$TMP/left.png" --trim-tiles 2 "$TMP/cube.obj" -o "$TMP/x.obj"
  check "tess --trim-tiles without --trim is a usage error" 2 "$CLI" tess --rate 2 --trim-tiles 2 2 "$TMP/cube.obj" -o "$TMP/x.obj"
  check "tess --trim without a file is a usage error" 2 "$CLI" tess --rate 2 "$TMP/cube.obj" -o "$TMP/x.obj" --trim
else
  S=$((S + 1)); echo "SKIP tess --trim: python3 (to write the mask PNGs) not found"
fi

# ---- shade and render (subdivision shading, seed 001; software pictures) ----
check "--help succeeds (shade, render)" 0 "$CLI" --help
contains "--help shows shade" "$TMP/out" "surfblend shade"
contains "--help shows render" "$TMP/out" "surfblend render"
check "shade succeeds" 0 "$CLI" shade --level 2 examples/data/creased_box.obj -o "$TMP/sh.obj"
contains "shade prints output and split vertices" "$TMP/err" "output vertices (.* refined, [0-9]* split)"
contains "shade prints where N_S was computed" "$TMP/err" "N_S computed at [0-9]* vertices ([0-9.]*%)"
nv=$(grep -c '^v ' "$TMP/sh.obj"); nn=$(grep -c '^vn ' "$TMP/sh.obj")
if [ "$nv" -gt 0 ] && [ "$nv" = "$nn" ]; then P=$((P + 1)); echo "ok shade writes one vn per v ($nv)"; else F=$((F + 1)); echo "FAIL shade: $nv v lines, $nn vn lines"; fi
if grep -q "($nv output vertices\|: $nv output vertices" "$TMP/err"; then P=$((P + 1)); echo "ok shade summary counts the written vertices"
else F=$((F + 1)); echo "FAIL shade summary does not say $nv output vertices"; head -n 2 "$TMP/err"; fi
if awk '/^f / { for (i = 2; i <= NF; ++i) { split($i, a, "/"); if (a[1] != a[3] || a[2] != "") exit 1 } n++ } END { exit !(n > 0) }' "$TMP/sh.obj"
then P=$((P + 1)); echo "ok shade faces are v//vn with the same index"; else F=$((F + 1)); echo "FAIL shade faces are not f a//a"; grep -m 2 '^f ' "$TMP/sh.obj"; fi
if awk -v n="$nv" '/^f / { for (i = 2; i <= NF; ++i) { split($i, a, "/"); if (a[1] < 1 || a[1] > n) exit 1 } } END { exit 0 }' "$TMP/sh.obj"
then P=$((P + 1)); echo "ok shade face indices are in range"; else F=$((F + 1)); echo "FAIL shade face index out of range"; fi
if awk '/^vn / { l = sqrt($2 * $2 + $3 * $3 + $4 * $4); if (l < 0.999 || l > 1.001) exit 1 }' "$TMP/sh.obj"
then P=$((P + 1)); echo "ok shade normals are unit length"; else F=$((F + 1)); echo "FAIL shade normals are not unit length"; fi
check "shaded output reads back" 0 "$CLI" info "$TMP/sh.obj"
check "shade --limit succeeds" 0 "$CLI" shade --level 2 --limit examples/data/creased_box.obj -o "$TMP/shl.obj"
if [ "$(grep -c '^v ' "$TMP/shl.obj")" = "$nv" ] && ! cmp -s <(grep '^v ' "$TMP/sh.obj") <(grep '^v ' "$TMP/shl.obj"); then
  P=$((P + 1)); echo "ok shade --limit writes other positions, as many"; else F=$((F + 1)); echo "FAIL shade --limit positions"; fi
check "shade --all-subdivided succeeds" 0 "$CLI" shade --level 2 --all-subdivided examples/data/creased_box.obj -o "$TMP/sha.obj"
contains "shade --all-subdivided computes N_S everywhere" "$TMP/err" "(100.0%)"
check "shade --averaging linear succeeds" 0 "$CLI" shade --level 2 --averaging linear examples/data/creased_box.obj -o "$TMP/shlin.obj"
if cmp -s <(grep -v '^#' "$TMP/sh.obj") <(grep -v '^#' "$TMP/shlin.obj"); then P=$((P + 1)); echo "ok --averaging linear is the default"
else F=$((F + 1)); echo "FAIL --averaging linear differs from the default"; fi
contains "shade output names the averaging" "$TMP/shlin.obj" "averaging linear"
check "shade --averaging bogus is a usage error" 2 "$CLI" shade --averaging bogus examples/data/creased_box.obj -o "$TMP/x.obj"
contains "--averaging bogus message" "$TMP/err" "--averaging needs linear, renormalized or spherical"
check "shade --averaging without a value is a usage error" 2 "$CLI" shade examples/data/creased_box.obj -o "$TMP/x.obj" --averaging
check "shade with every option succeeds" 0 "$CLI" shade --scheme catmark --level 2 --variant A --darts sharp --normals-level 0 \
  --weights-level 2 --p 2.5 --backend ref examples/data/creased_box.obj -o "$TMP/sho.obj"
if ! cmp -s "$TMP/sh.obj" "$TMP/sho.obj"; then P=$((P + 1)); echo "ok shade options change the normals"; else F=$((F + 1)); echo "FAIL shade options change nothing"; fi
check "shade --scheme loop succeeds" 0 "$CLI" shade --scheme loop --level 2 "$TMP/tet.obj" -o "$TMP/shloop.obj"
if [ "$(grep -c '^f ' "$TMP/shloop.obj")" = 64 ]; then P=$((P + 1)); echo "ok shade loop tetrahedron level 2 has 64 triangles"; else F=$((F + 1)); echo "FAIL shade loop face count"; fi
check "shade without -o is a usage error" 2 "$CLI" shade examples/data/creased_box.obj
check "shade --p 0 is a usage error" 2 "$CLI" shade --p 0 examples/data/creased_box.obj -o "$TMP/x.obj"
contains "--p 0 message" "$TMP/err" "--p needs a number > 0"
check "shade --p -1 is a usage error" 2 "$CLI" shade --p -1 examples/data/creased_box.obj -o "$TMP/x.obj"
check "shade --p x is a usage error" 2 "$CLI" shade --p x examples/data/creased_box.obj -o "$TMP/x.obj"
check "shade --level -1 is a usage error" 2 "$CLI" shade --level -1 examples/data/creased_box.obj -o "$TMP/x.obj"
check "shade --normals-level -1 is a usage error" 2 "$CLI" shade --normals-level -1 examples/data/creased_box.obj -o "$TMP/x.obj"
check "shade --weights-level x is a usage error" 2 "$CLI" shade --weights-level x examples/data/creased_box.obj -o "$TMP/x.obj"
check "shade --variant C is a usage error" 2 "$CLI" shade --variant C examples/data/creased_box.obj -o "$TMP/x.obj"
check "shade --darts blunt is a usage error" 2 "$CLI" shade --darts blunt examples/data/creased_box.obj -o "$TMP/x.obj"
check "shade --scheme bilinear is a usage error" 2 "$CLI" shade --scheme bilinear examples/data/creased_box.obj -o "$TMP/x.obj"
rm -f "$TMP/x.obj"
check "shade --level 11 is bad input" 1 "$CLI" shade --level 11 examples/data/creased_box.obj -o "$TMP/x.obj"
contains "shade level message names the limit" "$TMP/err" "limit"
if [ ! -e "$TMP/x.obj" ]; then P=$((P + 1)); echo "ok a failed shade leaves no file"; else F=$((F + 1)); echo "FAIL a failed shade left $TMP/x.obj"; fi
check "shade loop on quads is bad input" 1 "$CLI" shade --scheme loop examples/data/creased_box.obj -o "$TMP/x.obj"
check "shade of a missing file is bad input" 1 "$CLI" shade "$TMP/none.obj" -o "$TMP/x.obj"
check "shade to an unwritable path is bad input" 1 "$CLI" shade examples/data/creased_box.obj -o "$TMP/no/such/dir.obj"
contains "unwritable path is named" "$TMP/err" "cannot write"

# PNG: the 8-byte signature, then the IHDR chunk with width and height (big-endian)
png_size() { local h; h=$(od -An -tx1 -N24 "$1" 2>/dev/null | tr -d ' \n')
  if [ "${h:0:16}" != 89504e470d0a1a0a ] || [ "${h:24:8}" != 49484452 ]; then echo notpng; return; fi
  echo "$((16#${h:32:8}))x$((16#${h:40:8}))"; }
check "render succeeds" 0 "$CLI" render --level 2 examples/data/creased_box.obj -o "$TMP/r.png"
s=$(png_size "$TMP/r.png")
if [ "$s" = 640x480 ]; then P=$((P + 1)); echo "ok render writes a 640x480 PNG"; else F=$((F + 1)); echo "FAIL render output: $s"; fi
contains "render prints the object pixels" "$TMP/err" "640x480 ([0-9]* object pixels)"
for mode in --highlight --weights --normal-colors --edges; do
  check "render $mode succeeds" 0 "$CLI" render --level 2 $mode --size 120x90 examples/data/creased_box.obj -o "$TMP/r$mode.png"
  s=$(png_size "$TMP/r$mode.png")
  if [ "$s" = 120x90 ]; then P=$((P + 1)); echo "ok render $mode writes a 120x90 PNG"; else F=$((F + 1)); echo "FAIL render $mode output: $s"; fi
done
for n in limit subdivided blended; do
  check "render --normals $n succeeds" 0 "$CLI" render --level 2 --highlight --normals $n --size 160x120 --view 60,30 examples/data/creased_box.obj -o "$TMP/n$n.png"
done
if ! cmp -s "$TMP/nlimit.png" "$TMP/nblended.png" && ! cmp -s "$TMP/nsubdivided.png" "$TMP/nblended.png"; then
  P=$((P + 1)); echo "ok the three normal fields give three pictures"; else F=$((F + 1)); echo "FAIL the normal fields give the same picture"; fi
check "render --up turns the --view orbit about it" 0 "$CLI" render --level 2 --up 0,0,1 --view 30,20 --size 120x90 examples/data/creased_box.obj -o "$TMP/ru.png"
check "render --up with a NaN is a usage error" 2 "$CLI" render --up nan,0,1 --size 80x60 examples/data/creased_box.obj -o "$TMP/run.png"
check "render --positions refined succeeds" 0 "$CLI" render --level 2 --positions refined --size 160x120 --view 60,30 --highlight examples/data/creased_box.obj -o "$TMP/pr.png"
if ! cmp -s "$TMP/pr.png" "$TMP/nblended.png"; then P=$((P + 1)); echo "ok --positions refined differs from limit"; else F=$((F + 1)); echo "FAIL --positions refined changes nothing"; fi
check "render with shading options succeeds" 0 "$CLI" render --level 2 --variant A --darts sharp --normals-level 0 --weights-level 0 --p 3 \
  --zoom 2 --stripes 12 --backend ref --size 80x60 examples/data/creased_box.obj -o "$TMP/ro.png"
check "render a Loop surface succeeds" 0 "$CLI" render --scheme loop --level 3 --weights --size 80x60 "$TMP/tet.obj" -o "$TMP/rl.png"
check "render without -o is a usage error" 2 "$CLI" render examples/data/creased_box.obj
check "render with two modes is a usage error" 2 "$CLI" render --highlight --weights examples/data/creased_box.obj -o "$TMP/x.png"
check "render --normals bogus is a usage error" 2 "$CLI" render --normals bogus examples/data/creased_box.obj -o "$TMP/x.png"
check "render --positions bogus is a usage error" 2 "$CLI" render --positions bogus examples/data/creased_box.obj -o "$TMP/x.png"
check "render --size 0x10 is a usage error" 2 "$CLI" render --size 0x10 examples/data/creased_box.obj -o "$TMP/x.png"
check "render --size 100 is a usage error" 2 "$CLI" render --size 100 examples/data/creased_box.obj -o "$TMP/x.png"
check "render --view 30 is a usage error" 2 "$CLI" render --view 30 examples/data/creased_box.obj -o "$TMP/x.png"
check "render --zoom 0 is a usage error" 2 "$CLI" render --zoom 0 examples/data/creased_box.obj -o "$TMP/x.png"
check "render --p 0 is a usage error" 2 "$CLI" render --p 0 examples/data/creased_box.obj -o "$TMP/x.png"
check "render --level -1 is a usage error" 2 "$CLI" render --level -1 examples/data/creased_box.obj -o "$TMP/x.png"
rm -f "$TMP/x.png"
check "render --size 9000x10 is bad input" 1 "$CLI" render --size 9000x10 examples/data/creased_box.obj -o "$TMP/x.png"
contains "size message names the limit" "$TMP/err" "over the limit of 8192"
check "render --level 11 is bad input" 1 "$CLI" render --level 11 examples/data/creased_box.obj -o "$TMP/x.png"
if [ ! -e "$TMP/x.png" ]; then P=$((P + 1)); echo "ok a failed render leaves no file"; else F=$((F + 1)); echo "FAIL a failed render left $TMP/x.png"; fi
check "render to an unwritable path is bad input" 1 "$CLI" render --size 40x30 examples/data/creased_box.obj -o "$TMP/no/such/dir.png"
contains "unwritable picture path is named" "$TMP/err" "cannot write"

# a machine without libOSMesa (as on Mesa 25.1+): hide it in a private mount namespace (root only)
lib=$(ldconfig -p 2>/dev/null | awk '/libOSMesa\.so\.8 /{ print $NF; exit }')
if [ "$(id -u)" = 0 ] && [ -n "$lib" ] && unshare -m --propagation private true 2>/dev/null; then
  hide="mount --bind /dev/null $(readlink -f "$lib")"
  check "backends without libOSMesa" 0 unshare -m --propagation private sh -c "$hide && exec $CLI backends"
  contains "osmesa reported unavailable without libOSMesa" "$TMP/out" "^osmesa *unavailable .*libOSMesa.so.8 / .so.6 not found"
  check "refine --backend osmesa without libOSMesa falls back" 0 unshare -m --propagation private sh -c \
    "$hide && exec $CLI refine --backend osmesa --level 1 examples/data/creased_box.obj -o $TMP/o.obj"
  contains "the fall-back says why" "$TMP/err" "osmesa: unavailable (backend unavailable: libOSMesa"
else
  S=$((S + 1)); echo "SKIP hiding libOSMesa needs root, unshare and an installed libOSMesa"
fi

# ---- manifold blending (seed 000): tess, eval and render with --scheme manifold ----
check "tess --scheme manifold succeeds" 0 "$CLI" tess --scheme manifold --rate 4 examples/data/manifold_features.obj -o "$TMP/mf.obj"
contains "manifold tess is closed (no boundary edge)" "$TMP/err" "(18432 closed, 0 boundary)\|closed, 0 boundary"
got=$(grep -c '^f ' "$TMP/mf.obj")
if [ "$got" = 3072 ]; then P=$((P + 1)); echo "ok manifold tess: 96 quads x 4 x 4 x 2 = 3072 triangles"; else F=$((F + 1)); echo "FAIL manifold tess: $got triangles, wanted 3072"; fi
check "tess --scheme manifold --weights cinf succeeds" 0 "$CLI" tess --scheme manifold --weights cinf --rate 4 examples/data/manifold_features.obj -o "$TMP/mfc.obj"
d=$(objdiff "$TMP/mf.obj" "$TMP/mfc.obj")
if [ "$d" != count ] && awk -v d="$d" 'BEGIN { exit !(d > 1e-3) }'; then P=$((P + 1)); echo "ok C-infinity weights give another surface ($d)"
else F=$((F + 1)); echo "FAIL --weights cinf changed nothing ($d)"; fi
check "tess --weights bogus is a usage error" 2 "$CLI" tess --scheme manifold --weights bogus --rate 4 examples/data/manifold_features.obj -o "$TMP/x.obj"
check "refine --scheme manifold is bad input" 1 "$CLI" refine --scheme manifold examples/data/manifold_features.obj -o "$TMP/x.obj"
contains "refine --scheme manifold says why" "$TMP/err" "evaluated, not refined"
check "eval --scheme manifold succeeds" 0 "$CLI" eval --scheme manifold --random 5 examples/data/manifold_features.obj
got=$(grep -c . "$TMP/out")
if [ "$got" = 5 ]; then P=$((P + 1)); echo "ok eval --scheme manifold prints 5 lines"; else F=$((F + 1)); echo "FAIL eval --scheme manifold printed $got lines"; fi
check "render --scheme manifold succeeds" 0 "$CLI" render --scheme manifold --rate 6 --size 160x120 examples/data/manifold_features.obj -o "$TMP/mf.png"
contains "render --scheme manifold wrote a PNG" "$TMP/mf.png" "PNG"
check "render --rate without --scheme manifold is a usage error" 2 "$CLI" render --rate 6 examples/data/creased_box.obj -o "$TMP/x.png"
check "render --scheme manifold --weights (picture) is a usage error" 2 "$CLI" render --scheme manifold --weights examples/data/torus.obj -o "$TMP/x.png"
check "render --manifold-weights cinf succeeds" 0 "$CLI" render --scheme manifold --manifold-weights cinf --rate 4 --size 160x120 examples/data/torus.obj -o "$TMP/x.png"
contains "render --manifold-weights cinf says so" "$TMP/err" "C-infinity weights"
# one spelling: --manifold-weights everywhere; the old --weights is an alias (eval, tess: the
# manifold weights; render: the blend-weights picture, there --blend-weights)
check "tess --manifold-weights cinf succeeds" 0 "$CLI" tess --scheme manifold --manifold-weights cinf --rate 4 examples/data/manifold_features.obj -o "$TMP/mfm.obj"
if cmp -s "$TMP/mfc.obj" "$TMP/mfm.obj"; then P=$((P + 1)); echo "ok tess --weights cinf is --manifold-weights cinf"; else F=$((F + 1)); echo "FAIL tess --weights and --manifold-weights differ"; fi
"$CLI" eval --scheme manifold --weights cinf --random 7 examples/data/manifold_features.obj > "$TMP/ew1" 2>/dev/null
check "eval --manifold-weights cinf succeeds" 0 "$CLI" eval --scheme manifold --manifold-weights cinf --random 7 -o "$TMP/ew2" examples/data/manifold_features.obj
if [ -s "$TMP/ew1" ] && cmp -s "$TMP/ew1" "$TMP/ew2"; then P=$((P + 1)); echo "ok eval --weights cinf is --manifold-weights cinf"; else F=$((F + 1)); echo "FAIL eval --weights and --manifold-weights differ"; fi
"$CLI" eval --scheme manifold --random 7 examples/data/manifold_features.obj > "$TMP/ew3" 2>/dev/null
if ! cmp -s "$TMP/ew1" "$TMP/ew3"; then P=$((P + 1)); echo "ok eval --manifold-weights cinf changes the surface"; else F=$((F + 1)); echo "FAIL eval --manifold-weights cinf changes nothing"; fi
check "eval --manifold-weights bogus is a usage error" 2 "$CLI" eval --manifold-weights bogus --random 2 examples/data/manifold_features.obj
contains "--manifold-weights bogus message" "$TMP/err" "--manifold-weights needs hermite or cinf"
check "render --blend-weights succeeds" 0 "$CLI" render --level 2 --blend-weights --size 120x90 examples/data/creased_box.obj -o "$TMP/rbw.png"
if cmp -s "$TMP/rbw.png" "$TMP/r--weights.png"; then P=$((P + 1)); echo "ok render --weights is --blend-weights"; else F=$((F + 1)); echo "FAIL render --weights and --blend-weights differ"; fi
contains "render --blend-weights draws blend weights" "$TMP/err" "render blend weights"
check "render --scheme manifold --blend-weights is a usage error" 2 "$CLI" render --scheme manifold --blend-weights examples/data/torus.obj -o "$TMP/x.png"
contains "the manifold --blend-weights message names --manifold-weights" "$TMP/err" "--manifold-weights"
check "render --highlight --blend-weights is a usage error" 2 "$CLI" render --highlight --blend-weights examples/data/creased_box.obj -o "$TMP/x.png"
if [ -f "$TMP/left.png" ]; then
  check "render --scheme manifold --trim succeeds" 0 "$CLI" render --scheme manifold --rate 4 --trim "$TMP/left.png" --size 160x120 examples/data/torus.obj -o "$TMP/mft.png"
  contains "render --trim says it trimmed" "$TMP/err" "trimmed"
  check "render --scheme manifold untrimmed succeeds" 0 "$CLI" render --scheme manifold --rate 4 --size 160x120 examples/data/torus.obj -o "$TMP/mfu.png"
  a=$(grep -o "([0-9]* object pixels" "$TMP/err" | grep -o "[0-9]*")
  "$CLI" render --scheme manifold --rate 4 --trim "$TMP/left.png" --size 160x120 examples/data/torus.obj -o "$TMP/mft.png" 2> "$TMP/err2"
  b=$(grep -o "([0-9]* object pixels" "$TMP/err2" | grep -o "[0-9]*")
  if [ -n "$a" ] && [ -n "$b" ] && [ "$b" -lt "$a" ]; then P=$((P + 1)); echo "ok a trimmed picture covers fewer pixels ($b < $a)"
  else F=$((F + 1)); echo "FAIL trimmed picture pixels: '$b' vs untrimmed '$a'"; fi
fi

# ---- output files are written atomically: a failed command leaves no partial file, and an
# existing file at the output path untouched ----
printf 'keep\n' > "$TMP/keep.obj"
check "refine --level 11 over an existing file is bad input" 1 "$CLI" refine --level 11 examples/data/creased_box.obj -o "$TMP/keep.obj"
if [ "$(cat "$TMP/keep.obj")" = keep ]; then P=$((P + 1)); echo "ok a failed refine leaves the existing file"; else F=$((F + 1)); echo "FAIL a failed refine changed the existing file"; fi
# a failure while writing: a file size limit (SIGXFSZ ignored, so the write fails with EFBIG)
limited() { bash -c 'trap "" XFSZ; ulimit -f 16 && exec "$@"' limited "$@"; }
if limited true 2>/dev/null; then
  for c in "tess --rate 32 examples/data/creased_box.obj" "refine --level 5 examples/data/creased_box.obj" \
           "shade --level 4 examples/data/creased_box.obj" "render --size 1200x900 --normal-colors examples/data/creased_box.obj" \
           "eval --random 2000 examples/data/creased_box.obj"; do
    name=${c%% *}
    rm -f "$TMP/big.out"*
    check "$name failing while writing is bad input" 1 limited "$CLI" $c -o "$TMP/big.out"
    contains "$name says the write failed" "$TMP/err" "writing '$TMP/big.out' failed"
    left=$(ls "$TMP" | grep -c '^big\.out')
    if [ "$left" = 0 ]; then P=$((P + 1)); echo "ok $name failing while writing leaves no file"; else F=$((F + 1)); echo "FAIL $name left $(ls "$TMP" | grep '^big\.out')"; fi
    printf 'keep\n' > "$TMP/keep.out"
    limited "$CLI" $c -o "$TMP/keep.out" > /dev/null 2>&1
    if [ "$(cat "$TMP/keep.out")" = keep ] && [ "$(ls "$TMP" | grep -c '^keep\.out')" = 1 ]; then P=$((P + 1)); echo "ok $name failing while writing leaves the existing file"
    else F=$((F + 1)); echo "FAIL $name failing while writing changed the existing file"; fi
  done
else
  S=$((S + 1)); echo "SKIP a file size limit (ulimit -f) is not available"
fi
# killed by a signal: the temporary file goes too (SIGPIPE: the summary line's pipe closed, as
# `surfblend ... 2>&1 | head` does; SIGTERM in the middle of writing a large OBJ)
for c in "analyze --size 400x300 examples/data/creased_box.obj" "render --level 2 --size 400x300 examples/data/creased_box.obj"; do
  name=${c%% *}
  rm -f "$TMP/sig.out"*
  "$CLI" $c -o "$TMP/sig.out" 2>&1 | head -c 0
  st=${PIPESTATUS[0]}
  left=$(ls "$TMP" | grep -c '^sig\.out')
  if [ "$st" = 141 ] && [ "$left" = 0 ]; then P=$((P + 1)); echo "ok $name ended by SIGPIPE leaves no file"
  else F=$((F + 1)); echo "FAIL $name ended by SIGPIPE: exit $st, left $(ls "$TMP" | grep '^sig\.out' | tr '\n' ' ')"; fi
done
rm -f "$TMP/term.obj"*
"$CLI" tess --rate 128 examples/data/creased_box.obj -o "$TMP/term.obj" 2> /dev/null & # 60 MB, most of a second
pid=$!
for i in $(seq 1 3000); do ls "$TMP" | grep -q '^term\.obj\.tmp' && break; kill -0 $pid 2> /dev/null || break; sleep 0.01; done
kill -TERM $pid 2> /dev/null
wait $pid
st=$?
left=$(ls "$TMP" | grep -c '^term\.obj')
if [ "$st" = 143 ] && [ "$left" = 0 ]; then P=$((P + 1)); echo "ok tess killed (SIGTERM) while writing leaves no file"
elif [ "$st" = 0 ]; then S=$((S + 1)); echo "SKIP tess finished writing before SIGTERM arrived"
else F=$((F + 1)); echo "FAIL tess killed while writing: exit $st, left $(ls "$TMP" | grep '^term\.obj' | tr '\n' ' ')"; fi
check "refine -o /dev/null (not a regular file) succeeds" 0 "$CLI" refine --level 1 examples/data/creased_box.obj -o /dev/null
if [ -c /dev/null ]; then P=$((P + 1)); echo "ok /dev/null is still a device"; else F=$((F + 1)); echo "FAIL -o /dev/null replaced /dev/null"; fi
check "refine -o - writes standard output" 0 "$CLI" refine --level 1 examples/data/creased_box.obj -o -
contains "refine -o - wrote the OBJ" "$TMP/out" "^v "
if [ "$(ls "$TMP" | grep -c '\.tmp')" = 0 ]; then P=$((P + 1)); echo "ok no temporary files are left"; else F=$((F + 1)); echo "FAIL temporary files left: $(ls "$TMP" | grep '\.tmp')"; fi
touch "$TMP/perm.ref"; "$CLI" refine --level 1 examples/data/creased_box.obj -o "$TMP/perm.obj" 2>/dev/null
if [ "$(stat -c %a "$TMP/perm.obj")" = "$(stat -c %a "$TMP/perm.ref")" ]; then P=$((P + 1)); echo "ok an output file gets the usual permissions"
else F=$((F + 1)); echo "FAIL output permissions $(stat -c %a "$TMP/perm.obj"), a new file gets $(stat -c %a "$TMP/perm.ref")"; fi

# ---- analyze (seed 003): exact per-pixel surface quality pictures ----
for mode in reflection highlight zebra isophote curvature normals shaded; do
  check "analyze --mode $mode succeeds" 0 "$CLI" analyze --mode $mode --size 120x90 examples/data/creased_box.obj -o "$TMP/a$mode.png"
  s=$(png_size "$TMP/a$mode.png")
  if [ "$s" = 120x90 ]; then P=$((P + 1)); echo "ok analyze $mode writes a 120x90 PNG"; else F=$((F + 1)); echo "FAIL analyze $mode output: $s"; fi
done
contains "analyze reports the pixels it projected" "$TMP/err" "surface pixels (proxy [0-9]*, [0-9]* grown to the exact silhouette"
for light in stripes lattice circles; do
  check "analyze --light $light succeeds" 0 "$CLI" analyze --light $light --size 80x60 examples/data/creased_box.obj -o "$TMP/l$light.png"
done
mkpng "$TMP/light.png" 8 8 rgb-left
check "analyze --light FILE.png succeeds" 0 "$CLI" analyze --light "$TMP/light.png" --size 80x60 examples/data/creased_box.obj -o "$TMP/lf.png"
check "analyze --light of a missing file is bad input" 1 "$CLI" analyze --light "$TMP/none.png" --size 80x60 examples/data/creased_box.obj -o "$TMP/ax.png"
check "analyze a Loop surface with --eye/--target succeeds" 0 "$CLI" analyze --scheme loop --eye 3,2,4 --target 0,0,0 --up 0,1,0 --fov 40 --size 80x60 "$TMP/tet.obj" -o "$TMP/al.png"
check "analyze --up without --eye turns the --view orbit about it" 0 "$CLI" analyze --up 0,0,1 --view 30,20 --size 80x60 examples/data/creased_box.obj -o "$TMP/au.png"
check "analyze --up with a NaN is a usage error" 2 "$CLI" analyze --up 0,nan,1 --size 80x60 examples/data/creased_box.obj -o "$TMP/aun.png"
check "analyze --orthographic --polygon-based succeeds" 0 "$CLI" analyze --orthographic --polygon-based --level 1 --size 80x60 examples/data/creased_box.obj -o "$TMP/ao.png"
check "analyze --scheme manifold succeeds" 0 "$CLI" analyze --scheme manifold --mode curvature --curvature max --size 80x60 examples/data/manifold_features.obj -o "$TMP/am.png"
contains "analyze --mode curvature prints the range" "$TMP/err" "curvature .* colour map range"
check "analyze without -o is a usage error" 2 "$CLI" analyze examples/data/creased_box.obj
check "analyze --mode bogus is a usage error" 2 "$CLI" analyze --mode bogus examples/data/creased_box.obj -o "$TMP/ax.png"
check "analyze --eye without --target is a usage error" 2 "$CLI" analyze --eye 1,2,3 examples/data/creased_box.obj -o "$TMP/ax.png"
check "analyze --eye 1,2 is a usage error" 2 "$CLI" analyze --eye 1,2 --target 0,0,0 examples/data/creased_box.obj -o "$TMP/ax.png"
check "analyze --curvature without --mode curvature is a usage error" 2 "$CLI" analyze --curvature mean examples/data/creased_box.obj -o "$TMP/ax.png"
check "analyze --level 9 is a usage error" 2 "$CLI" analyze --level 9 examples/data/creased_box.obj -o "$TMP/ax.png"
check "analyze --eye at its --target is bad input" 1 "$CLI" analyze --eye 1,1,1 --target 1,1,1 examples/data/creased_box.obj -o "$TMP/ax.png"
contains "the error names the camera" "$TMP/err" "camera eye equals its target"
check "analyze --polygon-based --mode curvature is bad input" 1 "$CLI" analyze --polygon-based --mode curvature examples/data/creased_box.obj -o "$TMP/ax.png"
if [ ! -e "$TMP/ax.png" ]; then P=$((P + 1)); echo "ok a failed analyze leaves no file"; else F=$((F + 1)); echo "FAIL a failed analyze left $TMP/ax.png"; fi

# ---- fillet (seed 002): rolling-ball blending of a triangle mesh's sharp features ----
# a 90-degree fold: faces z = 0 (y in [-1, 0]) and y = 0 (z in [-1, 0]) meeting along the x axis
awk 'BEGIN { n = 20; m = 10;
  for (j = 0; j <= m; j++) for (i = 0; i <= n; i++) printf "v %g %g 0\n", 2 * i / n, -j / m;
  for (j = 1; j <= m; j++) for (i = 0; i <= n; i++) printf "v %g 0 %g\n", 2 * i / n, -j / m;
  for (j = 0; j < m; j++) for (i = 0; i < n; i++) { a = j * (n + 1) + i + 1; b = a + 1; c = a + n + 1; d = c + 1;
    printf "f %d %d %d\nf %d %d %d\n", a, c, b, b, c, d }
  for (j = 0; j < m; j++) for (i = 0; i < n; i++) {
    a = (j == 0 ? i + 1 : (m + 1) * (n + 1) + (j - 1) * (n + 1) + i + 1); b = a + 1;
    c = (m + 1) * (n + 1) + j * (n + 1) + i + 1; d = c + 1;
    printf "f %d %d %d\nf %d %d %d\n", a, b, c, b, d, c } }' > "$TMP/fold.obj"
check "fillet a fold succeeds" 0 "$CLI" fillet --radius 0.25 "$TMP/fold.obj" -o "$TMP/fold_f.obj"
contains "fillet reports the curve" "$TMP/err" "curve 0: open convex, 21 vertices (2 long), radius 0.25"
if [ "$(grep -c '^v ' "$TMP/fold_f.obj")" = "$(grep -c '^v ' "$TMP/fold.obj")" ] && [ "$(grep -c '^f ' "$TMP/fold_f.obj")" = "$(grep -c '^f ' "$TMP/fold.obj")" ]; then
  P=$((P + 1)); echo "ok fillet keeps the vertex and face counts"; else F=$((F + 1)); echo "FAIL fillet changed the counts"; fi
# the edge's middle vertex (x = 1) moves to the arc's middle: r (1 - 1/sqrt 2) from both faces
mid=$(awk '/^v /{k++; if (k == 11) print $3, $4}' "$TMP/fold_f.obj")
if awk -v m="$mid" 'BEGIN { split(m, a, " "); w = -0.25 * (1 - sqrt(0.5)); exit !(a[1] - w < 1e-4 && w - a[1] < 1e-4 && a[2] - w < 1e-4 && w - a[2] < 1e-4) }'; then
  P=$((P + 1)); echo "ok fillet puts the edge on the arc"; else F=$((F + 1)); echo "FAIL fillet: the edge's middle vertex is at ($mid)"; fi
check "fillet --profile conic:0.5 succeeds" 0 "$CLI" fillet --radius 0.25 --profile conic:0.5 "$TMP/fold.obj" -o "$TMP/fold_c.obj"
check "fillet --profile sharpen --curve succeeds" 0 "$CLI" fillet --radius 0.3 --profile sharpen --curve "$(seq -s, 0 20)" "$TMP/fold_f.obj" -o "$TMP/fold_s.obj"
check "fillet --profile hermite:0.5 --samples 60 --alpha 2 succeeds" 0 "$CLI" fillet --radius 0.25 --profile hermite:0.5 --samples 60 --alpha 2 "$TMP/fold.obj" -o "$TMP/fold_h.obj"
check "fillet without --radius is a usage error" 2 "$CLI" fillet "$TMP/fold.obj" -o "$TMP/fx.obj"
check "fillet --radius -1 is a usage error" 2 "$CLI" fillet --radius -1 "$TMP/fold.obj" -o "$TMP/fx.obj"
check "fillet --relax 10 succeeds" 0 "$CLI" fillet --radius 0.25 --relax 10 "$TMP/fold.obj" -o "$TMP/fold_r.obj"
check "fillet --relax -1 is a usage error" 2 "$CLI" fillet --radius 0.25 --relax -1 "$TMP/fold.obj" -o "$TMP/fx.obj"
check "fillet --profile hermite:50 is a usage error" 2 "$CLI" fillet --radius 0.2 --profile hermite:50 "$TMP/fold.obj" -o "$TMP/fx.obj"
check "fillet --profile bogus is a usage error" 2 "$CLI" fillet --radius 0.2 --profile bogus "$TMP/fold.obj" -o "$TMP/fx.obj"
check "fillet --curve 1,x is a usage error" 2 "$CLI" fillet --radius 0.2 --curve 1,x "$TMP/fold.obj" -o "$TMP/fx.obj"
check "fillet --radius 10 (too large) is bad input" 1 "$CLI" fillet --radius 10 "$TMP/fold.obj" -o "$TMP/fx.obj"
contains "the error says the offsets do not meet" "$TMP/err" "do not meet"
check "fillet a curve that is not a chain of edges is bad input" 1 "$CLI" fillet --radius 0.2 --curve 0,5 "$TMP/fold.obj" -o "$TMP/fx.obj"
contains "the error names the vertices" "$TMP/err" "no edge from vertex 0 to vertex 5"
check "fillet a quad mesh is bad input" 1 "$CLI" fillet --radius 0.2 examples/data/creased_box.obj -o "$TMP/fx.obj"
contains "the error asks for triangles" "$TMP/err" "triangle mesh"
check "fillet --angle 120 finds no feature" 1 "$CLI" fillet --radius 0.2 --angle 120 "$TMP/fold.obj" -o "$TMP/fx.obj"
if [ ! -e "$TMP/fx.obj" ]; then P=$((P + 1)); echo "ok a failed fillet leaves no file"; else F=$((F + 1)); echo "FAIL a failed fillet left $TMP/fx.obj"; fi
# a real mesh (made by other people): spot's creases at 60 degrees. A radius that suits them, and one
# too large for the surface around them: done, with a warning that counts the faces it turned over
REAL="$(dirname "$SHAPES")/real-meshes"
if [ -f "$REAL/spot.obj" ]; then
  check "fillet spot.obj --angle 60 --radius 0.02 succeeds" 0 "$CLI" fillet --angle 60 --radius 0.02 "$REAL/spot.obj" -o "$TMP/spot_f.obj"
  if grep -q "turned over" "$TMP/err"; then F=$((F + 1)); echo "FAIL fillet spot r 0.02 turned faces over"; else P=$((P + 1)); echo "ok fillet spot r 0.02 turns no face over"; fi
  check "fillet spot.obj --angle 60 --radius 0.1 succeeds" 0 "$CLI" fillet --angle 60 --radius 0.1 "$REAL/spot.obj" -o "$TMP/spot_f.obj"
  contains "a radius too large for spot warns of turned faces" "$TMP/err" "warning: [0-9]* faces turned over: the radius is too large"
  # at 30 degrees spot has 114 creases, some too flat or uneven for r = 0.02: refused whole, or with
  # --skip-failed those stay sharp and the rest are filleted
  check "fillet spot.obj --angle 30 --radius 0.02 is refused (a curve cannot be filleted)" 1 "$CLI" fillet --angle 30 --radius 0.02 "$REAL/spot.obj" -o "$TMP/spot_s.obj"
  if [ ! -e "$TMP/spot_s.obj" ]; then P=$((P + 1)); echo "ok the refused fillet wrote nothing"; else F=$((F + 1)); echo "FAIL the refused fillet wrote $TMP/spot_s.obj"; fi
  check "fillet spot.obj --angle 30 --radius 0.02 --skip-failed succeeds" 0 "$CLI" fillet --angle 30 --radius 0.02 --skip-failed "$REAL/spot.obj" -o "$TMP/spot_s.obj"
  contains "--skip-failed names the curves left sharp" "$TMP/err" "skipped, left sharp"
  contains "--skip-failed counts them" "$TMP/err" "curves filleted ([1-9][0-9]* skipped)"
else echo "skip fillet on spot.obj: $REAL not found"; fi

# vertex counts against OpenSubdiv (osd_agree --counts prints "name count" per shape)
if [ -d "$SHAPES" ] && [ -x "$BUILD/osd_agree" ]; then
  for L in 1 2; do
    "$BUILD/osd_agree" --counts "$SHAPES" "$L" > "$TMP/counts" 2>/dev/null
    while read -r name want; do
      [ -n "$name" ] || continue
      if "$CLI" refine --level "$L" "$SHAPES/$name.obj" -o "$TMP/r.obj" 2> "$TMP/err"; then
        got=$(grep -c '^v ' "$TMP/r.obj")
        if [ "$got" = "$want" ]; then P=$((P + 1)); else F=$((F + 1)); echo "FAIL refine $name level $L: $got vertices, OpenSubdiv $want"; fi
      else
        F=$((F + 1)); echo "FAIL refine $name level $L refused: $(head -n 1 "$TMP/err")"
      fi
    done < "$TMP/counts"
  done
fi
echo "$P passed, $F failed, $S skipped"
[ "$F" -eq 0 ]
