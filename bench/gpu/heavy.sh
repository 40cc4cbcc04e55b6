#!/bin/bash
# The backend table in one call: Sponza baked on the CPU backend, on Vulkan and with --backend auto,
# interleaved, for each workload; process wall seconds per run and a per-stage breakdown from each
# bake's JSON summary (--progress json: timings_s, rays, backend decision).
#
#   bench/gpu/heavy.sh GIBAKE SPONZA.gltf [--gpu] [--tiny] [--runs N] [--threads T] [--out DIR] [--extra "ARGS"]
#
# --gpu:  Vulkan runs take the first GPU (--backend vulkan); without it they run on lavapipe
#         (--vulkan-device lavapipe), which is how it is checked on machines without a GPU.
# --tiny: small workloads (seconds on 2 cores), to check the script itself.
# --extra: more bake arguments for every run (e.g. "--reconstruction-check off").
# The full table (no --tiny): light (a 16x7x10 grid) x 256;
# 32x15x21 x 256 and x 2048; 64x30x42 x 512 and x 2048; --probe-spacing 1 x 1024; --sun
# 0.3,-1,0.2:100000, 4 bounces, path; and "default", the bake's own grid (fitted to the scene)
# with every bake default (adaptive rays from --rays 512: --target-error 0.05, --ray-budget 2048).
# The bake's defaults are adaptive, so the fixed-ray workloads pass --target-error 0
# (exactly --rays a probe); an --extra that gives --target-error replaces it for every workload.
set -euo pipefail
# shellcheck source=bench/gpu/common.sh
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
G=${1:?gibake binary}; SCENE=${2:?Sponza.gltf}; shift 2
GPU=0; OUT=${TMPDIR:-/tmp}/gibake_heavy
own_option() { if [ "$1" = --gpu ]; then GPU=1; TOOK=1; fi; }
bench_options heavy.sh "$@"
if [ $TINY = 1 ]; then
  WORKLOADS=("default:--rays 16" "8x4x5:--probe-counts 8,4,5 --rays 32 --target-error 0"
             "spacing4:--probe-spacing 4 --rays 16 --target-error 0")
else
  WORKLOADS=("default:" "light:--probe-counts 16,7,10 --rays 256 --target-error 0"
             "32x15x21x256:--probe-counts 32,15,21 --rays 256 --target-error 0"
             "32x15x21x2048:--probe-counts 32,15,21 --rays 2048 --target-error 0"
             "64x30x42x512:--probe-counts 64,30,42 --rays 512 --target-error 0"
             "64x30x42x2048:--probe-counts 64,30,42 --rays 2048 --target-error 0"
             "spacing1x1024:--probe-spacing 1 --rays 1024 --target-error 0")
fi
VK="--backend vulkan"; [ $GPU = 1 ] || VK="--backend vulkan --vulkan-device lavapipe"
BASE="--ddgi --sun 0.3,-1,0.2:100000 --bounces 4 --gather path --threads $THREADS --progress json $EXTRA"
BACKENDS=("cpu:--backend cpu" "vulkan:$VK" "auto:--backend auto")

# One bake: prints "name backend run wall" and keeps the summary line in $OUT/name.backend.run.json.
bake() {
  local name=$1 backend=$2 run=$3 args=$4 flags=$5
  local wall err="$OUT/$name.$backend.$run.err"
  # shellcheck disable=SC2086
  wall=$(timed_bake "heavy.sh: $name $backend" "$err" "$G" "$SCENE" $BASE $args $flags --out "$OUT/$name.$backend.gibake") ||
    return 1
  grep '"event":"summary"' "$err" > "$OUT/$name.$backend.$run.json" || true
  echo "$name $backend $run $wall"
}

echo "# $(date -u +%FT%TZ) $G threads=$THREADS gpu=$GPU tiny=$TINY runs=$RUNS" | tee "$OUT/walls.txt"
for w in "${WORKLOADS[@]}"; do
  workload "$w"
  for run in $(seq 1 "$RUNS"); do
    for b in "${BACKENDS[@]}"; do bake "$name" "${b%%:*}" "$run" "$args" "${b#*:}" | tee -a "$OUT/walls.txt"; done
  done
done

# The breakdown: per workload and backend, the best wall time and that run's stages.
if command -v python3 > /dev/null; then
  python3 - "$OUT" <<'PY'
import json, sys, glob, os
out = sys.argv[1]
walls = {}
for line in open(os.path.join(out, "walls.txt")):
    if line.startswith("#"): continue
    name, backend, run, wall = line.split()
    walls.setdefault((name, backend), []).append((float(wall), run))
for (name, backend), runs in walls.items():
    best, run = min(runs)
    path = os.path.join(out, f"{name}.{backend}.{run}.json")
    s = json.loads(open(path).read()) if os.path.getsize(path) else {}
    rays = s.get("rays", {}) if isinstance(s.get("rays"), dict) else {}
    b = s.get("backend", {})
    print(f"\n{name} {backend}: wall {best:.2f} s (runs {', '.join(f'{w:.2f}' for w, _ in sorted(runs, key=lambda r: r[1]))})"
          f"; ran on {b.get('name', '?')}" + (f" ({b.get('reason')})" if b.get('auto') else ""))
    if b.get("estimate_s"): print(f"  auto's estimate: cpu {b['estimate_s']['cpu']:.2f} s, vulkan {b['estimate_s']['vulkan']:.2f} s")
    for stage, sec in s.get("timings_s", {}).items(): print(f"  {stage:44s} {sec:8.3f} s")
PY
else
  echo "(no python3: the summaries are in $OUT/*.json)"
fi
