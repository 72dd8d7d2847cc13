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
check "unknown command is a usage error" 2 "$CLI" frobnicate
check "refine without -o is a usage error" 2 "$CLI" refine examples/data/creased_box.obj
check "bad --level is a usage error" 2 "$CLI" refine --level x examples/data/creased_box.obj -o "$TMP/o.obj"
check "missing file is bad input" 1 "$CLI" info "$TMP/does-not-exist.obj"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n' > "$TMP/bad.obj"
check "out-of-range index is bad input" 1 "$CLI" info "$TMP/bad.obj"
contains "bad input message names the line" "$TMP/err" "line 4"
check "level over the limit is bad input" 1 "$CLI" refine --level 11 examples/data/creased_box.obj -o "$TMP/o.obj"
contains "level message names the limit" "$TMP/err" "limit"
check "loop on quads is bad input" 1 "$CLI" refine --scheme loop examples/data/creased_box.obj -o "$TMP/o.obj"
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
