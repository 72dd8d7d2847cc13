#!/bin/bash
# The glTF validation wrapper (tests/web/validate.mjs) on files written here from scratch
# (tests/web/gltf_fixtures.mjs): valid ones pass, broken ones fail with the validator's codes.
# Closes with "N passed, N failed, N skipped"; without node or gltf-validator: one skip, reason given
# (a failure instead when SFB_REQUIRE_WEB is set, as on CI).
set -u
cd "$(dirname "$0")/../.."
BUILD=${BUILD:-build}
export SFB_NODE_DIR=${SFB_NODE_DIR:-$BUILD/node}
W=$BUILD/web/validate; rm -rf "$W"; mkdir -p "$W"
P=0; F=0
pass() { P=$((P + 1)); echo "ok $1"; }
fail() { F=$((F + 1)); echo "FAIL $1"; }
unavailable() { # skipped with the reason; failed when SFB_REQUIRE_WEB is set (CI)
  if [ -n "${SFB_REQUIRE_WEB:-}" ]; then echo "FAIL validate: $1 (SFB_REQUIRE_WEB is set)"; echo "0 passed, 1 failed, 0 skipped"; exit 1; fi
  echo "SKIP validate: $1"; echo "0 passed, 0 failed, 1 skipped"; exit 0
}
command -v node >/dev/null || unavailable "node not found"
[ -f "$SFB_NODE_DIR/node_modules/gltf-validator/package.json" ] || unavailable "gltf-validator not installed under $SFB_NODE_DIR (make deps-web)"

node tests/web/gltf_fixtures.mjs "$W" || { fail "fixtures written"; echo "$P passed, $F failed, 0 skipped"; exit 1; }

# expect NAME RC [CODE...]: validate.mjs on $W/NAME exits RC and prints each CODE
expect() {
  local name=$1 rc=$2 got out; shift 2
  out=$(node tests/web/validate.mjs "$W/$name" 2>&1); got=$?
  echo "$out" | sed 's/^/    /'
  [ "$got" = "$rc" ] || { fail "$name: exit $got, expected $rc"; return; }
  for code in "$@"; do echo "$out" | grep -q " $code " || { fail "$name: no $code in the output"; return; }; done
  pass "$name (exit $rc${*:+: $*})"
}
expect tri.glb 0
expect tri.gltf 0
expect tri_unused.gltf 0 # one info (an unused accessor): allowed
node tests/web/validate.mjs "$W/tri_unused.gltf" | grep -qx "ok $W/tri_unused.gltf (1 infos)" && pass "infos counted" || fail "infos counted"
expect bad_minmax.gltf 1 ACCESSOR_MAX_MISMATCH
expect bad_index.glb 1 ACCESSOR_INDEX_OOB
expect missing_bin.gltf 1 IO_ERROR
expect no_position.gltf 1 MESH_PRIMITIVE_NO_POSITION # a warning alone fails
node tests/web/validate.mjs "$W/tri.glb" "$W/nonexistent.glb" > "$W/missing.out" 2>&1
[ $? = 1 ] && grep -q "^FAIL $W/nonexistent.glb" "$W/missing.out" && pass "unreadable file fails" || fail "unreadable file fails"

# several files, one line each, and the JSON report
out=$(node tests/web/validate.mjs --json "$W/report.json" "$W/tri.glb" "$W/bad_index.glb" "$W/tri.gltf"); rc=$?
lines=$(echo "$out" | grep -cE "^(ok|FAIL) ")
[ "$rc" = 1 ] && [ "$lines" = 3 ] && pass "three files: exit 1, three lines" || fail "three files: exit $rc, $lines lines"
node -e '
  const r = JSON.parse(require("fs").readFileSync(process.argv[1], "utf8"));
  const ok = r.files.length === 3 && r.files[0].ok && !r.files[1].ok && r.files[1].errors === 1 && r.files[2].ok &&
    r.files[1].report.issues.messages.some((m) => m.code === "ACCESSOR_INDEX_OOB") && typeof r.validator === "string";
  process.exit(ok ? 0 : 1);' "$W/report.json" && pass "JSON report" || fail "JSON report"
node tests/web/validate.mjs --json "$W/r2.json" "$W/tri.glb" "$W/tri.gltf" >/dev/null && pass "all valid: exit 0" || fail "all valid: exit 0"

# usage errors: exit 2
node tests/web/validate.mjs > /dev/null 2>&1; [ $? = 2 ] && pass "no files: exit 2" || fail "no files: exit 2"
node tests/web/validate.mjs --bogus "$W/tri.glb" > /dev/null 2>&1; [ $? = 2 ] && pass "unknown option: exit 2" || fail "unknown option: exit 2"
node tests/web/validate.mjs --json > /dev/null 2>&1; [ $? = 2 ] && pass "--json without a file: exit 2" || fail "--json without a file: exit 2"
echo "$P passed, $F failed, 0 skipped"
[ "$F" = 0 ]
