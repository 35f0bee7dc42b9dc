#!/usr/bin/env bash
# The README's main job on bundled data. Until the fused replay lands, it runs the most complete
# tool there is on bundled real data and prints its result.
set -euo pipefail
BUILD=${1:-build}
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BIN="$ROOT/$BUILD/bin"
echo "SRI-GVINS demo: no tool is available yet"
