# Shared by the end-to-end scripts apps/iblkit/cli_test*.sh: `source "$(dirname "$0")/cli_check.sh" "$1"`
# with $1 the iblkit binary. Sets BIN, a temporary folder T (removed on exit), PROBE (a blender-data
# probe), the counters pass/fail/skip, and check().
BIN="$1"
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
PROBE=/usr/share/blender/datafiles/studiolights/world/forest.exr
fail=0; pass=0; skip=0

# check NAME EXPECT(ok|fail) [PATTERN] -- CMD...
# Runs CMD; counts a failure when it crashes, exits against EXPECT, lacks PATTERN (extended regex) in its
# output, or fails with a message longer than three lines.
check() {
  local name="$1" want="$2" pat="$3"; shift 4
  local out rc
  out=$("$@" 2>&1); rc=$?
  if [ $rc -ge 128 ]; then echo "FAIL $name: crashed (signal $((rc-128))): $out"; fail=$((fail+1)); return; fi
  if [ "$want" = ok ] && [ $rc -ne 0 ]; then echo "FAIL $name: exit $rc: $out"; fail=$((fail+1)); return; fi
  if [ "$want" = fail ] && [ $rc -eq 0 ]; then echo "FAIL $name: expected failure, got success: $out"; fail=$((fail+1)); return; fi
  if [ -n "$pat" ] && ! grep -qE -- "$pat" <<<"$out"; then echo "FAIL $name: output lacks /$pat/: $out"; fail=$((fail+1)); return; fi
  if [ "$want" = fail ] && [ "$(wc -l <<<"$out")" -gt 3 ]; then echo "FAIL $name: error message is not short: $out"; fail=$((fail+1)); return; fi
  pass=$((pass+1))
}
