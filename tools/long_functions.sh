#!/bin/sh
# Lists functions longer than N lines (default 120) in the given C files: "lines file:line name".
# Usage: tools/long_functions.sh [-n N] FILE...
n=120
if [ "$1" = "-n" ]; then n=$2; shift 2; fi
awk -v max="$n" '
  FNR == 1 { depth = 0; start = 0 }
  {
    line = $0
    gsub(/"([^"\\]|\\.)*"/, "", line); gsub(/\/\*.*\*\//, "", line)
    if (depth == 0 && line ~ /^[A-Za-z_].*\(/ && line !~ /;[ \t]*$/) { sig = line; sigline = FNR }
    o = gsub(/\{/, "{", line); c = gsub(/\}/, "}", line)
    if (depth == 0 && o > 0) { start = FNR; name = sig; at = sigline }
    depth += o - c
    if (depth == 0 && start > 0) {
      len = FNR - at + 1
      if (len > max && name ~ /\(/) { sub(/\(.*/, "", name); k = split(name, w, /[ \t*]+/); printf "%5d %s:%d %s\n", len, FILENAME, at, w[k] }
      start = 0
    }
  }' "$@" | sort -rn
