#!/usr/bin/env bash
# README.md is assembled from docs/sections/: edit those, then run this script.
set -euo pipefail
cd "$(dirname "$0")/sections"
first=1
for s in intro subcommands render golden oracle check compare grade development; do
  [ "$first" = 1 ] || echo
  first=0
  cat "$s.md"
done > ../../README.md
