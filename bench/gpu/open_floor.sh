#!/usr/bin/env bash
# The driver's floor under a Vulkan bake: bench_gpu_open run as RUNS fresh processes (the first open
# after boot is slower, so the first run is printed apart), each run's steps on one line, then the
# process's own wall time. Usage: bench/gpu/open_floor.sh build/bench/gpu/bench_gpu_open [runs] [device]
set -euo pipefail
B=${1:?bench_gpu_open binary}; RUNS=${2:-5}; DEVICE=${3:-}
for r in $(seq 1 "$RUNS"); do
  t0=$(date +%s.%N)
  out=$("$B" $DEVICE)
  t1=$(date +%s.%N)
  steps=$(echo "$out" | grep -v '^device ' | awk '{printf "%s %s s, ", $1, $2}')
  device=$(echo "$out" | sed -n 's/^device //p')
  echo "run $r ($device): ${steps}process $(awk "BEGIN{printf \"%.4f\", $t1 - $t0}") s"
done
