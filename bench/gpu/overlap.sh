#!/bin/bash
# Chunks in flight: the Vulkan bake of one build (NEW_GIBAKE) against another (OLD_GIBAKE, the one
# to compare with) and the CPU backend, interleaved run by run, on the heavy, medium, light and
# default workloads; per run the process wall time, and per bake the stages (--progress json
# summary: timings_s) and the device's own notes: the trace pipeline's wall time beside the
# device's busy time (timestamps) and the host time it overlapped, the path kernels' device time,
# the set-up, the write.
#
#   bench/gpu/overlap.sh NEW_GIBAKE OLD_GIBAKE SPONZA.gltf [--gpu] [--tiny] [--runs N] [--threads T]
#                        [--out DIR] [--extra "ARGS"]
#
# --gpu:  Vulkan runs take the first GPU; without it lavapipe (--vulkan-device lavapipe).
# --tiny: small workloads (seconds on 2 cores), to check the script itself.
# The workloads (Sponza, --sun 0.3,-1,0.2:100000, 4 bounces, path): heavy 64x30x42 x 2048,
# medium 32x15x21 x 2048, light 16x7x10 x 256 rays, each with --target-error 0 (exactly --rays a
# probe: the bake's defaults are adaptive rays and a grid fitted to the scene); "default" is
# the bake's own grid x --rays 256 with its default adaptive rays. An --extra that gives
# --target-error replaces the workloads' --target-error 0.
# OLD_GIBAKE may be "-" to leave it out. On a GPU machine, with the bundle of bench/gpu/bundle.sh
# and the build to compare with beside it (docs/BENCHMARKS.md, "Chunks in flight"):
#   bench/gpu/overlap.sh /tmp/gb/gibake /tmp/gb/gibake_main /tmp/sponza/Sponza.gltf --gpu --runs 2 \
#     --threads 16 --extra "--reconstruction-check off"
set -euo pipefail
# shellcheck source=bench/gpu/common.sh
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
NEW=${1:?new gibake}; OLD=${2:?old gibake or -}; SCENE=${3:?Sponza.gltf}; shift 3
GPU=0; OUT=${TMPDIR:-/tmp}/gibake_overlap
own_option() { if [ "$1" = --gpu ]; then GPU=1; TOOK=1; fi; }
bench_options overlap.sh "$@"
if [ $TINY = 1 ]; then
  WORKLOADS=("heavy:--probe-counts 16,8,10 --rays 128 --target-error 0"
             "medium:--probe-counts 8,4,5 --rays 128 --target-error 0" "default:--rays 16")
else
  WORKLOADS=("heavy:--probe-counts 64,30,42 --rays 2048 --target-error 0"
             "medium:--probe-counts 32,15,21 --rays 2048 --target-error 0"
             "light:--probe-counts 16,7,10 --rays 256 --target-error 0" "default:--rays 256")
fi
VK="--backend vulkan"; [ $GPU = 1 ] || VK="--backend vulkan --vulkan-device lavapipe"
BASE="--ddgi --sun 0.3,-1,0.2:100000 --bounces 4 --gather path --threads $THREADS --progress json $EXTRA"
RUNNERS=("cpu:$NEW:--backend cpu" "vulkan_new:$NEW:$VK")
[ "$OLD" = "-" ] || RUNNERS+=("vulkan_old:$OLD:$VK")

# One bake: prints "name runner run wall"; its JSON events stay in $OUT/name.runner.run.err.
bake() {
  local name=$1 runner=$2 exe=$3 run=$4 args=$5 flags=$6 wall
  # shellcheck disable=SC2086
  wall=$(timed_bake "overlap.sh: $name $runner" "$OUT/$name.$runner.$run.err" "$exe" "$SCENE" $BASE $args $flags \
    --out "$OUT/$name.$runner.gibake") || return 1
  echo "$name $runner $run $wall"
}

echo "# $(date -u +%FT%TZ) new=$NEW old=$OLD threads=$THREADS gpu=$GPU tiny=$TINY runs=$RUNS" | tee "$OUT/walls.txt"
for w in "${WORKLOADS[@]}"; do
  workload "$w"
  for run in $(seq 1 "$RUNS"); do
    for r in "${RUNNERS[@]}"; do
      IFS=: read -r runner exe flags <<<"$r"
      bake "$name" "$runner" "$exe" "$run" "$args" "$flags" | tee -a "$OUT/walls.txt"
    done
  done
  # The two Vulkan bakes must agree byte for byte (the pipeline changes no result).
  if [ "$OLD" != "-" ]; then
    if cmp -s "$OUT/$name.vulkan_new.gibake" "$OUT/$name.vulkan_old.gibake"; then echo "$name: new and old Vulkan bakes identical"
    else echo "$name: new and old Vulkan bakes DIFFER"; fi | tee -a "$OUT/walls.txt"
  fi
done

command -v python3 > /dev/null || { echo "(no python3: the events are in $OUT/*.err)"; exit 0; }
python3 "$(dirname "${BASH_SOURCE[0]}")/walls.py" "$OUT" 4 vulkan:
