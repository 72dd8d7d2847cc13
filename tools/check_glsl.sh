#!/bin/bash
# Validates every shader in backends/gl/glsl/ with glslangValidator as the backend compiles it:
# desktop GLSL 4.30 core and GLSL ES 3.10 (a shader that uses SFB_LENGTH: for each value the
# backend may use, 1..16), and checks that backends/gl/shaders.h is up to date. Closing line: "N passed, N failed, N skipped".
set -u
cd "$(dirname "$0")/.."
PASS=0; FAIL=0; SKIP=0
TMP=$(mktemp -d); trap 'rm -rf "$TMP"' EXIT
if tools/embed_glsl.sh > "$TMP/shaders.h" && cmp -s "$TMP/shaders.h" backends/gl/shaders.h; then
  echo "PASS embedded shaders up to date"; PASS=$((PASS + 1))
else
  echo "FAIL backends/gl/shaders.h is stale against backends/gl/glsl/ (run 'make embed-glsl')"; FAIL=$((FAIL + 1))
fi
if ! command -v glslangValidator >/dev/null; then
  echo "SKIP glslangValidator not installed (Debian package glslang-tools)"; SKIP=$((SKIP + 1))
else
  for f in backends/gl/glsl/*.glsl; do
    stage=$(basename "$f" .glsl); stage=${stage##*.}
    lengths=-
    if grep -q SFB_LENGTH "$f"; then lengths="1 2 3 4 7 16"; fi
    for variant in desktop es; do
      for n in $lengths; do
        out="$TMP/$(basename "$f" .glsl)-$variant-$n.glsl"
        if [ $variant = desktop ]; then printf '#version 430 core\n' > "$out"
        else printf '#version 310 es\nprecision highp float;\nprecision highp int;\n' > "$out"; fi
        if [ "$n" != - ]; then printf '#define SFB_LENGTH %d\n' "$n" >> "$out"; fi
        cat "$f" >> "$out"
        what="$f $variant"; if [ "$n" != - ]; then what="$what SFB_LENGTH=$n"; fi
        if log=$(glslangValidator -S "$stage" "$out" 2>&1); then PASS=$((PASS + 1)); echo "PASS $what"
        else FAIL=$((FAIL + 1)); echo "FAIL $what:"; echo "$log"; fi
      done
    done
  done
fi
echo "$PASS passed, $FAIL failed, $SKIP skipped"
[ "$FAIL" -eq 0 ]
