#!/bin/sh
# Lists functions longer than N lines (default 120) in the given C files: "lines file:line name".
# A function is a top-level brace block whose opening follows a line with "name(" at column 0;
# preprocessor lines (and their continuations) are skipped. Usage: tools/long_functions.sh [-n N] FILE...
n=120
if [ "$1" = "-n" ]; then n=$2; shift 2; fi
awk -v max="$n" '
  FNR == 1 { depth = 0; start = 0; sig = ""; cont = 0 }
  {
    line = $0
    if (cont || line ~ /^[ \t]*#/) { cont = (line ~ /\\$/); next }
    gsub(/"([^"\\]|\\.)*"/, "", line); gsub(/'"'"'([^'"'"'\\]|\\.)*'"'"'/, "", line); gsub(/\/\*.*\*\//, "", line); sub(/\/\/.*/, "", line)
    if (depth == 0 && line ~ /^[A-Za-z_][A-Za-z_0-9 \t*]*\(/ && line !~ /;[ \t]*$/) { sig = line; sigline = FNR }
    o = gsub(/\{/, "{", line); c = gsub(/\}/, "}", line)
    if (depth == 0 && o > 0) { start = FNR; name = sig; at = sigline; sig = "" }
    depth += o - c
    if (depth == 0 && start > 0) {
      if (name != "" && FNR - at + 1 > max) { sub(/\(.*/, "", name); k = split(name, w, /[ \t*]+/); printf "%5d %s:%d %s\n", FNR - at + 1, FILENAME, at, w[k] }
      start = 0
    }
  }' "$@" | sort -rn
