#!/usr/bin/env bash
# 1280x720 `lit` preview of Sponza on 2 threads: Mrays/s against the bake's own tracing.
# Usage: bench/bench_preview.sh [build-dir] [runs]   (assets under ../shared/assets by default)
set -euo pipefail
BUILD=${1:-build}
RUNS=${2:-3}
G="$BUILD/cli/gibake"
SCENE=${GIBAKE_ASSETS_DIR:-$(dirname "$0")/../../shared/assets}/sponza/Sponza.gltf
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
"$G" bake "$SCENE" --ddgi --sun 0.3,-1,0.2:100000 --threads 2 --progress lines --out "$TMP/sponza.gibake" 2>&1 |
  grep -E "rays:|seconds:"
for i in $(seq "$RUNS"); do
  "$G" preview "$SCENE" --bake "$TMP/sponza.gibake" --out "$TMP/lit.png" --size 1280x720 --threads 2 \
    --progress lines 2>&1 | grep -E "^  lit:"
  /usr/bin/time -f "  wall %e s (import + prepare + render + PNG)" "$G" preview "$SCENE" --bake "$TMP/sponza.gibake" \
    --out "$TMP/lit.png" --size 1280x720 --threads 2 --progress lines 2>&1 | grep -E "wall"
done
