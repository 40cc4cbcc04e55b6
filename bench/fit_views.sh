#!/usr/bin/env bash
# The surface fit's effect on the picture: Sponza in sunlight baked with --surface-fit on and off
# at each level, each bake measured by its own reconstruction check from one view's camera
# (independent points and paths: the check's seed differs from the fit's, its patches are the
# view's 8x8-pixel blocks). Prints one line a bake: level, fit, view, the check's figures, wall.
#   bench/fit_views.sh GIBAKE SPONZA.gltf [OUTDIR]   env: LEVELS (default "default final"),
#                                                   FITS ("on off"), EXTRA_BAKE_ARGS (e.g. --backend vulkan)
set -euo pipefail
G=${1:?usage: bench/fit_views.sh GIBAKE SPONZA.gltf [OUTDIR]}
S=${2:?usage: bench/fit_views.sh GIBAKE SPONZA.gltf [OUTDIR]}
O=${3:-/tmp/gibake_fit_views}
mkdir -p "$O"
declare -A CAMERA=([court]="--check-camera default" [arcade]="--check-camera 9,5,3.5,-9,3,-3.5,0,1,0 --check-fov 70")
for level in ${LEVELS:-default final}; do
  for fit in ${FITS:-on off}; do
    for view in court arcade; do
      log="$O/$level.$fit.$view.log"
      # shellcheck disable=SC2086
      /usr/bin/time -f "%e" -o "$O/time" "$G" "$S" --ddgi --sun 0.3,-1,0.2:100000 --quality "$level" \
        --surface-fit "$fit" ${CAMERA[$view]} --check-patches 512 --check-rays 256 ${EXTRA_BAKE_ARGS:-} \
        --out "$O/$level.$fit.gibake" > "$log" 2>&1
      check=$(grep -o "reconstruction error.*" "$log" | sed 's/reconstruction error (camera, //')
      echo "$level fit $fit $view: $check; wall $(cat "$O/time") s"
    done
  done
done
