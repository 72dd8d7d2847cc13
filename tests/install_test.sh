#!/bin/bash
# make install into temporary prefixes: the header, its backends/ headers, the programs and
# surfblend.pc land where they should (DESTDIR staging too), examples/01_minimal.c builds
# against the installed copy with `pkg-config --cflags --libs surfblend` alone (in a folder of
# its own, so nothing resolves to the source tree) and prints what the in-tree build prints,
# and make uninstall removes it all. Closes with "N passed, N failed, N skipped".
set -u
cd "$(dirname "$0")/.."
BUILD=${BUILD:-build}
CC=${CC:-cc}
T=$(pwd)/$BUILD/install-test; rm -rf "$T"; mkdir -p "$T/src"
P=0; F=0
pass() { P=$((P + 1)); echo "ok $1"; }
fail() { F=$((F + 1)); echo "FAIL $1"; }
finish() { echo "$P passed, $F failed, 0 skipped"; [ "$F" = 0 ]; exit; }
command -v pkg-config > /dev/null || { fail "pkg-config not found (Debian package pkg-config: make deps-test)"; finish; }
M="make -s --no-print-directory BUILD=$BUILD"

# 1. a plain prefix
PFX=$T/prefix
$M install PREFIX="$PFX" > "$T/install.log" 2>&1 && pass "make install PREFIX=$PFX" || { fail "make install"; cat "$T/install.log"; finish; }
cmp -s surfblend.h "$PFX/include/surfblend/surfblend.h" && pass "surfblend.h installed" || fail "surfblend.h installed"
missing=0; n=0
for h in $(find backends -name '*.h'); do n=$((n + 1)); cmp -s "$h" "$PFX/include/surfblend/$h" || { missing=1; echo "  not installed: $h"; }; done
[ "$missing" = 0 ] && pass "the $n backends/ headers installed beside it" || fail "backends/ headers"
"$PFX/bin/surfblend" --help > /dev/null 2>&1 && pass "bin/surfblend runs" || fail "bin/surfblend runs"
export PKG_CONFIG_PATH=$PFX/lib/pkgconfig
ver=$(sed -nE 's/^#define SFB_VERSION_(MAJOR|MINOR|PATCH) ([0-9]+).*/\2/p' src/sfb_api.h | paste -sd. -)
[ "$(pkg-config --modversion surfblend 2>&1)" = "$ver" ] && pass "pkg-config: version $ver" || fail "pkg-config --modversion: $(pkg-config --modversion surfblend 2>&1)"
flags=$(pkg-config --cflags --libs surfblend)
echo "pkg-config --cflags --libs surfblend: $flags"
case "$flags" in *"-I$PFX/include/surfblend"*"-lm"*"-lpthread"*"-ldl"*) pass "pkg-config flags";; *) fail "pkg-config flags: $flags";; esac

# 2. a program built against the installed copy only
cp examples/01_minimal.c "$T/src/main.c"
printf '/* the one implementation file of a user program */\n#define SURFBLEND_IMPLEMENTATION\n#define SURFBLEND_ALL_BACKENDS\n#include "surfblend.h"\n' > "$T/src/impl.c"
if (cd "$T/src" && $CC -std=c99 -O2 -Wall -Wextra -c impl.c $(pkg-config --cflags surfblend) -o impl.o &&
    $CC -std=c99 -O2 -Wall -Wextra -c main.c $(pkg-config --cflags surfblend) -o main.o &&
    $CC main.o impl.o -o minimal $(pkg-config --libs surfblend)) > "$T/build.log" 2>&1; then
  pass "examples/01_minimal.c built with pkg-config --cflags --libs surfblend"
else fail "examples/01_minimal.c against the installed copy"; cat "$T/build.log"; finish; fi
[ -x "$BUILD/examples/01_minimal" ] || $M "$BUILD/examples/01_minimal" > /dev/null 2>&1
"$BUILD/examples/01_minimal" > "$T/intree.out" 2>&1; rc1=$?
"$T/src/minimal" > "$T/installed.out" 2>&1; rc2=$?
if [ "$rc1" = 0 ] && [ "$rc2" = 0 ] && cmp -s "$T/intree.out" "$T/installed.out"; then
  pass "its output is the in-tree build's ($(wc -l < "$T/installed.out") lines: $(head -n 1 "$T/installed.out"))"
else fail "output differs from the in-tree build (exit $rc1, $rc2)"; diff "$T/intree.out" "$T/installed.out" | head -n 10; fi

# 3. DESTDIR staging: files under DESTDIR, surfblend.pc naming the final prefix
STAGE=$T/stage
$M install DESTDIR="$STAGE" PREFIX=/opt/surfblend > "$T/stage.log" 2>&1 && [ -f "$STAGE/opt/surfblend/include/surfblend/surfblend.h" ] &&
  [ -x "$STAGE/opt/surfblend/bin/surfblend" ] && pass "make install DESTDIR=... PREFIX=/opt/surfblend stages the files" ||
  { fail "DESTDIR staging"; cat "$T/stage.log"; }
grep -qx "prefix=/opt/surfblend" "$STAGE/opt/surfblend/lib/pkgconfig/surfblend.pc" 2>/dev/null && pass "staged surfblend.pc: prefix=/opt/surfblend" ||
  fail "staged surfblend.pc prefix"
# the staged copy through the sysroot (as a packager's build would): the same program again
if (cd "$T/src" && PKG_CONFIG_PATH=$STAGE/opt/surfblend/lib/pkgconfig PKG_CONFIG_SYSROOT_DIR=$STAGE \
      sh -c '$0 -std=c99 -c main.c $(pkg-config --cflags surfblend) -o main2.o && $0 main2.o impl.o -o minimal2 $(pkg-config --libs surfblend)' "$CC" &&
    ./minimal2 | cmp -s - "$T/intree.out") > "$T/stage-build.log" 2>&1; then
  pass "built against the staged copy (PKG_CONFIG_SYSROOT_DIR), same output"
else fail "build against the staged copy"; cat "$T/stage-build.log"; fi

# 4. uninstall
$M uninstall PREFIX="$PFX" > /dev/null 2>&1
left=$(find "$PFX" -type f | wc -l)
[ "$left" = 0 ] && pass "make uninstall removes every installed file" || { fail "make uninstall left $left files"; find "$PFX" -type f | head; }
finish
