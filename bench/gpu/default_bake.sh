#!/bin/bash
# Adaptive rays on the device: the DEFAULT Sponza bake (`--ddgi --sun 0.3,-1,0.2:100000`:
# the fitted grid, --target-error 0.1, --rays 256 up to --max-rays 4096) on `--backend vulkan`,
# `--backend cpu` and `--backend auto`, interleaved run by run; per run the process wall time, and
# per runner its best run's stages (--progress json summary: timings_s) and the device's notes (the
# trace pipeline's wall time, device busy, host reduction, recording; the adaptive route's line).
#
#   bench/gpu/default_bake.sh GIBAKE SPONZA.gltf [--lavapipe] [--tiny] [--runs N] [--threads T]
#                             [--old OLD_GIBAKE] [--out DIR] [--extra "ARGS"]
#
# --lavapipe: Vulkan runs on lavapipe (--vulkan-device lavapipe), to check the script here.
# --tiny:     a small grid (--probe-counts 6,3,4 --rays 32), seconds on lavapipe.
# --old:      also bake Vulkan with OLD_GIBAKE (e.g. a build to compare against) in the same interleaving.
# On a GPU machine (docs/BENCHMARKS.md, "Adaptive rays on the device"), with the bundle of
# bench/gpu/bundle.sh:
#   bench/gpu/default_bake.sh /tmp/gb/gibake /tmp/sponza/Sponza.gltf --runs 2 --threads 16
set -euo pipefail
# shellcheck source=bench/gpu/common.sh
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
EXE=${1:?gibake}; SCENE=${2:?Sponza.gltf}; shift 2
LAVAPIPE=0; OLD=""; OUT=${TMPDIR:-/tmp}/gibake_default_bake
own_option() {
  case $1 in
    --lavapipe) LAVAPIPE=1; TOOK=1 ;;
    --old) OLD=$2; TOOK=2 ;;
  esac
}
bench_options default_bake.sh "$@"
ARGS="--ddgi --sun 0.3,-1,0.2:100000 --threads $THREADS --progress json $EXTRA"
[ $TINY = 1 ] && ARGS="$ARGS --probe-counts 6,3,4 --rays 32"
DEV=""; [ $LAVAPIPE = 1 ] && DEV="--vulkan-device lavapipe"
RUNNERS=("vulkan:$EXE:--backend vulkan $DEV" "cpu:$EXE:--backend cpu" "auto:$EXE:--backend auto $DEV")
[ -n "$OLD" ] && RUNNERS+=("vulkan_old:$OLD:--backend vulkan $DEV")

echo "# $(date -u +%FT%TZ) exe=$EXE old=${OLD:--} threads=$THREADS lavapipe=$LAVAPIPE tiny=$TINY runs=$RUNS" |
  tee "$OUT/walls.txt"
for run in $(seq 1 "$RUNS"); do
  for r in "${RUNNERS[@]}"; do
    IFS=: read -r runner exe flags <<<"$r"
    # shellcheck disable=SC2086
    wall=$(timed_bake "default_bake.sh: $runner" "$OUT/$runner.$run.err" "$exe" "$SCENE" $ARGS $flags \
      --out "$OUT/$runner.gibake") || exit 1
    echo "$runner $run $wall" | tee -a "$OUT/walls.txt"
  done
done
# The Vulkan bake against the CPU's (the agreement check): states, texels at 1e-2 lux.
"$EXE" verify "$OUT/vulkan.gibake" --against "$OUT/cpu.gibake" --tolerance 0.01 | tail -4 | tee -a "$OUT/walls.txt"

command -v python3 > /dev/null || { echo "(no python3: the events are in $OUT/*.err)"; exit 0; }
python3 "$(dirname "${BASH_SOURCE[0]}")/walls.py" "$OUT" 3 vulkan: backend auto
