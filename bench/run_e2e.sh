#!/usr/bin/env bash
# The end-to-end benchmarks that time the CLI on paper-scale inputs (what `make bench` runs after the
# micro-benchmarks). Each writes a few GB into a temporary folder and takes minutes on 2 cores:
#   lab capture: 4397 mirror balls of 250² of low-scene1 (issue 4, target ≤ 300 s)
#   ILF build:   4397 mirror balls of 250² into a 64³ grid of 25 coefficients (issue 5, target ≤ 300 s, ≤ 2 GB)
# Usage: bench/run_e2e.sh [BUILD_DIR]   (IBLKIT_E2E=lab or ilf runs only that one)
set -euo pipefail
BUILD=${1:-build}
here=$(dirname "$0")
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
which=${IBLKIT_E2E:-lab,ilf}
if [[ ",$which," == *",lab,"* ]]; then
  echo "== lab capture (bench/lab_capture.sh)"
  bash "$here/lab_capture.sh" "$BUILD/iblkit" 4397 "$work/lab"
  rm -rf "$work/lab"
fi
if [[ ",$which," == *",ilf,"* ]]; then
  echo "== ILF build (bench/ilf_e2e.sh)"
  bash "$here/ilf_e2e.sh" "$BUILD/iblkit" "$work/ilf"
fi
echo "Record the figures in bench/RESULTS.md with the date and the machine."
