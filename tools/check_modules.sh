#!/bin/sh
# Builds the library from src/*.c as separate translation units (each with only the public API
# and src/sfb_internal.h before it, src/sfb_module.h), as C99 and as C++, with warnings as errors
# and -Wmissing-prototypes (a function shared between modules must be declared in
# sfb_internal.h), links them with the examples and runs those. So no module depends on the
# order of tools/amalgamate.sh or on another module's private (static) names.
# Usage: tools/check_modules.sh [BUILD_DIR]
set -e
cd "$(dirname "$0")/.."
out=${1:-build}/modules
CC=${CC:-cc}
CXX=${CXX:-c++}
mkdir -p "$out/c" "$out/cxx"
objs_c=""; objs_cxx=""
for f in src/*.c src/patch/*.c src/fillet/*.c; do
  b=$(echo "${f#src/}" | sed "s,/,_,g; s,\.c$,,")
  $CC -std=c99 -pedantic -Wall -Wextra -Wmissing-prototypes -Werror -O0 -I. -include src/sfb_module.h -c "$f" -o "$out/c/$b.o"
  $CXX -std=c++11 -Wall -Wextra -Werror -O0 -I. -include src/sfb_module.h -x c++ -c "$f" -o "$out/cxx/$b.o"
  objs_c="$objs_c $out/c/$b.o"; objs_cxx="$objs_cxx $out/cxx/$b.o"
done
echo "check-modules: $(ls src/*.c src/patch/*.c src/fillet/*.c | wc -l) modules compile alone (C99 and C++11)"
for ex in examples/*.c; do
  b=$(basename "$ex" .c)
  $CC -std=c99 -Wall -Wextra -Werror -O0 -I. "$ex" $objs_c -o "$out/$b" -lm -lpthread -ldl
  $CXX -std=c++11 -O0 -I. -x c++ "$ex" -x none $objs_cxx -o "$out/$b-cxx" -lm -lpthread -ldl
  "$out/$b" > "$out/$b.log" 2>&1 || { echo "check-modules: FAILED: $b on the separately compiled modules"; cat "$out/$b.log"; exit 1; }
  "$out/$b-cxx" > "$out/$b-cxx.log" 2>&1 || { echo "check-modules: FAILED: $b (C++) on the separately compiled modules"; cat "$out/$b-cxx.log"; exit 1; }
done
echo "check-modules: the examples link and run on them"
