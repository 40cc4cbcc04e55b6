#!/usr/bin/env bash
# Sharded bakes on this machine's cores (docs/BENCHMARKS.md, "Sharded bakes"):
#  1. Sponza (--sun 0.3,-1,0.2:100000, a 48x20x30 grid, 256 rays) baked whole, then as 1, 2 and 4
#     shards started together (each with nproc/N threads, at least 1) followed by the merge: wall
#     times, the shards' summed CPU time, and a cmp with the whole bake; both gathers.
#  2. The merge alone for a bake of 100,352 probes (64x28x56, 16 rays) in 4 parts: wall time and
#     peak memory (GNU time), both gathers (the probe gather's merge runs the bounce passes).
#   bench/shard_bench.sh [GIBAKE] [WORKDIR]     (prints Markdown tables)
set -euo pipefail
gibake="$(realpath "${1:-build/cli/gibake}")"
work="${2:-$(mktemp -d /tmp/gibake-shard-bench.XXXXXX)}"
sponza="$(realpath "${SPONZA:-$(dirname "$0")/../../shared/assets/sponza/Sponza.gltf}")"  # the shared assets beside the checkout
sun=(--sun 0.3,-1,0.2:100000)
cores="$(nproc)"
mkdir -p "$work"
cd "$work"
timed() {  # timed LOG CMD...: GNU time's wall seconds, CPU seconds and peak KB into LOG
  /usr/bin/time -f "%e %U %S %M" -o "$1" "${@:2}" >/dev/null 2>"$1.err"
}
field() { awk -v f="$2" '{ print $f }' "$1"; }
cpu() { awk '{ printf "%.1f", $2 + $3 }' "$1"; }

echo "machine: $cores cores; $(date -u +%F)"
echo
echo "| gather | shards | whole bake (s) | shards wall (s) | merge (s) | sharded total (s) | CPU whole / shards (s) | identical |"
echo "| --- | ---: | ---: | ---: | ---: | ---: | --- | --- |"
for gather in path probes; do
  opts=("$sponza" --ddgi "${sun[@]}" --probe-counts 48,20,30 --gather "$gather" --leak-audit off --ray-budget 0)
  timed whole.t "$gibake" "${opts[@]}" --out whole.gibake
  for n in 1 2 4; do
    threads=$((cores / n)); [ $threads -ge 1 ] || threads=1
    rm -f part_*.gibake
    start=$(date +%s.%N)
    pids=()
    for ((i = 0; i < n; i++)); do
      timed "shard_$i.t" "$gibake" "${opts[@]}" --shard "$i/$n" --threads "$threads" --out "part_$i.gibake" &
      pids+=($!)
    done
    for p in "${pids[@]}"; do wait "$p"; done
    shards_wall=$(echo "$(date +%s.%N) - $start" | bc)
    parts=(); for ((i = 0; i < n; i++)); do parts+=("part_$i.gibake"); done
    timed merge.t "$gibake" merge "${parts[@]}" --out merged.gibake
    shard_cpu=$(cat shard_*.t | awk '{ s += $2 + $3 } END { printf "%.1f", s }')
    rm -f shard_*.t
    same=$(cmp -s whole.gibake merged.gibake && echo yes || echo NO)
    printf "| %s | %d | %.2f | %.2f | %.2f | %.2f | %s / %s | %s |\n" "$gather" "$n" "$(field whole.t 1)" "$shards_wall" \
      "$(field merge.t 1)" "$(echo "$shards_wall + $(field merge.t 1)" | bc)" "$(cpu whole.t)" "$shard_cpu" "$same"
  done
done

echo
echo "| gather | probes | parts (MB) | output (MB) | merge wall (s) | merge peak memory (MiB) | identical |"
echo "| --- | ---: | ---: | ---: | ---: | ---: | --- |"
for gather in path probes; do
  opts=("$sponza" --ddgi "${sun[@]}" --probe-counts 64,28,56 --rays 16 --gather "$gather" --leak-audit off --ray-budget 0
    --closed-mesh-check off)
  timed big.t "$gibake" "${opts[@]}" --out big.gibake
  rm -f bigpart_*.gibake
  for i in 0 1 2 3; do "$gibake" "${opts[@]}" --shard "$i/4" --out "bigpart_$i.gibake" >/dev/null 2>&1; done
  timed bigmerge.t "$gibake" merge bigpart_0.gibake bigpart_1.gibake bigpart_2.gibake bigpart_3.gibake --out bigmerged.gibake
  parts_mb=$(du -cb bigpart_*.gibake | tail -n 1 | awk '{ printf "%.0f", $1 / 1e6 }')
  out_mb=$(stat -c %s bigmerged.gibake | awk '{ printf "%.0f", $1 / 1e6 }')
  same=$(cmp -s big.gibake bigmerged.gibake && echo yes || echo NO)
  printf "| %s | 100352 | %s | %s | %.2f | %.0f | %s |\n" "$gather" "$parts_mb" "$out_mb" "$(field bigmerge.t 1)" \
    "$(echo "$(field bigmerge.t 4) / 1024" | bc -l)" "$same"
done
rm -f ./*.gibake
