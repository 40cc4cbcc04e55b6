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
EXE=${1:?gibake}; SCENE=${2:?Sponza.gltf}; shift 2
LAVAPIPE=0; TINY=0; RUNS=2; EXTRA=""; THREADS=$(nproc); OLD=""; OUT=${TMPDIR:-/tmp}/gibake_default_bake
while [ $# -gt 0 ]; do
  case $1 in
    --lavapipe) LAVAPIPE=1 ;;
    --tiny) TINY=1 ;;
    --runs) RUNS=$2; shift ;;
    --threads) THREADS=$2; shift ;;
    --old) OLD=$2; shift ;;
    --out) OUT=$2; shift ;;
    --extra) EXTRA=$2; shift ;;
    *) echo "default_bake.sh: unknown argument $1" >&2; exit 1 ;;
  esac
  shift
done
mkdir -p "$OUT"
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
    err="$OUT/$runner.$run.err"
    t0=$(date +%s.%N)
    # shellcheck disable=SC2086
    if ! "$exe" bake "$SCENE" $ARGS $flags --out "$OUT/$runner.gibake" 2>"$err"; then
      echo "default_bake.sh: $runner failed:" >&2; tail -3 "$err" >&2; exit 1
    fi
    t1=$(date +%s.%N)
    echo "$runner $run $(awk "BEGIN{printf \"%.3f\", $t1 - $t0}")" | tee -a "$OUT/walls.txt"
  done
done
# The Vulkan bake against the CPU's (the agreement check): states, texels at 1e-2 lux.
"$EXE" verify "$OUT/vulkan.gibake" --against "$OUT/cpu.gibake" --tolerance 0.01 | tail -4 | tee -a "$OUT/walls.txt"

command -v python3 > /dev/null || { echo "(no python3: the events are in $OUT/*.err)"; exit 0; }
python3 - "$OUT" <<'PY'
import json, sys, os
out = sys.argv[1]
walls = {}
for line in open(os.path.join(out, "walls.txt")):
    parts = line.split()
    if line.startswith("#") or len(parts) != 3: continue
    runner, run, wall = parts
    try: walls.setdefault(runner, []).append((float(wall), run))
    except ValueError: pass
for runner, runs in walls.items():
    best, run = min(runs)
    summary, notes = {}, []
    for line in open(os.path.join(out, f"{runner}.{run}.err")):
        try: e = json.loads(line)
        except ValueError: continue
        if e.get("event") == "summary": summary = e
        elif any(k in str(e.get("message", "")) for k in ("vulkan:", "backend", "auto")): notes.append(e["message"])
    print(f"\n{runner}: wall {best:.2f} s (runs {', '.join(f'{w:.2f}' for w, _ in sorted(runs, key=lambda r: r[1]))})")
    for stage, sec in summary.get("timings_s", {}).items(): print(f"  {stage:44s} {sec:8.3f} s")
    for n in notes: print(f"  | {n}")
PY
