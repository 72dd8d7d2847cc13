#!/bin/sh
# Writes backends/gl/shaders.h to stdout: every backends/gl/glsl/* file as a C string
# constant sfb__glsl_<name> (dots become underscores). Usage: tools/embed_glsl.sh > backends/gl/shaders.h
set -e
cd "$(dirname "$0")/.."
echo "/* GENERATED from backends/gl/glsl/ by \`make embed-glsl\`; edit the .glsl sources instead. */"
echo
echo "/* A kernel may be longer than the 4095 characters C99 promises for one string literal; GCC,"
echo " * Clang and MSVC (64 KiB) take far more, so -pedantic's warning is silenced here only. */"
echo "#if defined(__GNUC__)"
echo "#pragma GCC diagnostic push"
echo "#pragma GCC diagnostic ignored \"-Woverlength-strings\""
echo "#endif"
for f in backends/gl/glsl/*; do
  name=$(basename "$f" | tr '.-' '__')
  echo
  echo "/* $f */"
  echo "static const char sfb__glsl_$name[] ="
  sed -e 's/\\/\\\\/g' -e 's/"/\\"/g' -e 's/^/    "/' -e 's/$/\\n"/' "$f"
  echo "    ;"
done
echo
echo "#if defined(__GNUC__)"
echo "#pragma GCC diagnostic pop"
echo "#endif"
