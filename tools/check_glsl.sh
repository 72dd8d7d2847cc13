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
        # the header sfb__gl_shader puts before every kernel (backends/gl/sfb_gl.h)
        if [ $variant = desktop ]; then printf '#version 430 core\n#define SFB_PRECISE precise\n' > "$out"
        else printf '%s\n' '#version 310 es' \
          '#if defined(GL_EXT_gpu_shader5)' '#extension GL_EXT_gpu_shader5 : enable' '#define SFB_PRECISE precise' \
          '#elif defined(GL_OES_gpu_shader5)' '#extension GL_OES_gpu_shader5 : enable' '#define SFB_PRECISE precise' \
          '#else' '#define SFB_PRECISE' '#endif' 'precision highp float;' 'precision highp int;' > "$out"; fi
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
