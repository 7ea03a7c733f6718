#!/usr/bin/env bash
# End-to-end checks of the CLI as a user meets it (registered with CTest as cli_smoke).
set -u
BIN="$1"
fail=0; pass=0
check() {  # check NAME EXPECTED_RC CMD...
  local name="$1" want="$2"; shift 2
  local out rc
  out=$("$@" 2>&1); rc=$?
  if [ "$want" = "0" ] && [ $rc -ne 0 ]; then echo "FAIL $name: exit $rc: $out"; fail=$((fail+1)); return; fi
  if [ "$want" != "0" ] && [ $rc -eq 0 ]; then echo "FAIL $name: expected failure, got success: $out"; fail=$((fail+1)); return; fi
  pass=$((pass+1))
}
check help 0 "$BIN" --help
echo "$pass passed, $fail failed"
[ $fail -eq 0 ]
