#!/usr/bin/env bash
# Voxel GI speed (docs/BENCHMARKS.md, "Voxel GI"):
#  1. Sponza baked with --vxgi at --vxgi-res $RES (--sun 0.3,-1,0.2:100000, otherwise the defaults):
#     voxelize, radiance and mip seconds from the bake's JSON summary, wall time and peak memory.
#  2. Diffuse cone queries on that file: $QUERIES points spread over the coarsest volume (a fixed
#     awk generator, so every run asks the same), normals cycling over 14 directions; `gibake
#     sample --timing` on the CPU (one thread) and with --backend vulkan on $DEVICE (uploads and
#     readback included, so also a run of 1000 to show the fixed cost); queries per second, and the
#     largest difference between the two backends' answers (the kernel is the GLSL include).
# Needs only the gibake binary, awk and GNU time: it runs from the device bundle (bench/gpu/bundle.sh).
#   bench/vxgi_bench.sh [GIBAKE] [WORKDIR]
#   env: SPONZA (Sponza.gltf), RES (256), QUERIES (100000), DEVICE (--vulkan-device; empty: the
#        first GPU), CLIPMAPS (1), EXTRA (more bake options)
# On this 2-core VM, tiny, on lavapipe: RES=16 QUERIES=2000 DEVICE=lavapipe bench/vxgi_bench.sh
set -euo pipefail
gibake="$(realpath "${1:-build/cli/gibake}")"
work="${2:-$(mktemp -d /tmp/gibake-vxgi-bench.XXXXXX)}"
sponza="$(realpath "${SPONZA:-$(dirname "$0")/../../shared/assets/sponza/Sponza.gltf}")"
res="${RES:-256}" queries="${QUERIES:-100000}" device="${DEVICE:-}" clipmaps="${CLIPMAPS:-1}"
mkdir -p "$work"
cd "$work"
dev=()
[ -n "$device" ] && dev=(--vulkan-device "$device")

echo "machine: $(nproc) cores; $(date -u +%F); $("$gibake" info --devices 2>/dev/null | head -3 | tr '\n' ' ')"
# shellcheck disable=SC2086
/usr/bin/time -f "%e %M" -o bake.t "$gibake" "$sponza" --vxgi --vxgi-res "$res" --vxgi-clipmaps "$clipmaps" \
  --sun 0.3,-1,0.2:100000 --progress json ${EXTRA:-} --out sponza.gibake 2>bake.log >/dev/null
summary=$(grep '"event":"vxgi"' bake.log | tail -1)
num() { echo "$summary" | sed -n "s/.*\"$1\":\([0-9.e+-]*\).*/\1/p"; }
echo
echo "| --vxgi-res | voxels | surface voxels | voxelize s | radiance s | mips s | wall s | peak RSS GiB | file MB |"
echo "| ---: | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"
dims=$(echo "$summary" | sed -n 's/.*"dims":\[\([0-9,]*\)\].*/\1/p' | tr ',' 'x')
read -r wall rss <bake.t
echo "| $res | $dims | $(num surface_voxels) | $(num voxelize) | $(num radiance) | $(num mips) | $wall |" \
  "$(awk -v k="$rss" 'BEGIN { printf "%.2f", k / 1048576 }') | $(( $(stat -c %s sponza.gibake) / 1000000 )) |"

# The coarsest volume's box (the last "vxgi volume" line of `gibake info`).
box=$("$gibake" info sponza.gibake | grep '^vxgi volume' | tail -1)
points() {  # points N FILE: N points inside the box, normals over 14 directions
  echo "$box" | awk -v n="$1" '{
    split($4, d, "x"); s = $7; g = $0; sub(/.*grid_min \[/, "", g); sub(/\].*/, "", g); split(g, o, ",")
    m = split("1,0,0 -1,0,0 0,1,0 0,-1,0 0,0,1 0,0,-1 k,k,k k,k,-k k,-k,k k,-k,-k -k,k,k -k,k,-k -k,-k,k -k,-k,-k", dirs, " ")
    for (i = 1; i <= m; ++i) { gsub(/k/, "0.57735027", dirs[i]); nn[i - 1] = dirs[i] }
    srand(7)
    for (i = 0; i < n; ++i) {
      printf "%.5f,%.5f,%.5f,%s\n", o[1] + rand() * d[1] * s, o[2] + rand() * d[2] * s, o[3] + rand() * d[3] * s,
             nn[i % 14]
    }
  }' >"$2"
}
points "$queries" q.csv
points 1000 q1k.csv
rate() { sed -n 's/.*: \([0-9]*\) vxgi queries .* in \([0-9.]*\) s.*/\1 \2/p' "$1" | awk '{ printf "%s queries in %s s: %.0f / s", $1, $2, $1 / $2 }'; }
"$gibake" sample sponza.gibake --points q.csv --source vxgi --timing >cpu.csv 2>cpu.log
echo
echo "CPU (one thread): $(rate cpu.log)"
if "$gibake" sample sponza.gibake --points q.csv --source vxgi --timing --backend vulkan "${dev[@]}" >gpu.csv 2>gpu.log; then
  "$gibake" sample sponza.gibake --points q1k.csv --source vxgi --timing --backend vulkan "${dev[@]}" >/dev/null 2>gpu1k.log
  echo "Vulkan: $(rate gpu.log); 1000 queries: $(rate gpu1k.log)"
  # Largest relative difference per value (floor 1e-3 lux) and the share beyond 1e-3 relative.
  paste -d, cpu.csv gpu.csv | awk -F, '$7 != "" {
    for (c = 7; c <= 9; ++c) { a = $c; b = $(c + 9); r = (a > b ? a - b : b - a) / (a > 1e-3 ? a : 1e-3)
      if (r > w) w = r; if (r > 1e-3) ++loose; ++n } }
    END { printf "CPU vs Vulkan: %d values, %d beyond 1e-3 relative, worst %.2e\n", n, loose, w }'
else
  echo "Vulkan: not run ($(tail -1 gpu.log))"
fi
echo "(files in $work)"
