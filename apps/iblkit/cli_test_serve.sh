#!/usr/bin/env bash
# `iblkit serve` under hostile clients, with real sockets (issue 32 §1; CTest cli_serve): serve_test.py
# beside this script drives every case (Host, Range, the link-swap race, slow clients, idle
# connections under address-space and open-file limits, parallel downloads).
set -u
BIN="$1"
command -v python3 >/dev/null || { echo "cli_serve: no python3: skipped"; exit 0; }
exec timeout 300 python3 "$(dirname "$0")/serve_test.py" "$BIN"
