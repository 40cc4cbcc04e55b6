#!/usr/bin/env bash
# The picture at full size: for each view, a bake (default settings plus EXTRA_BAKE_ARGS)
# rendered through the loader's sampler against a high-sample path-traced reference, 8x8-pixel
# blocks of luminance (`preview --diff`), beside the bake's own reconstruction check from the same
# camera (`--check-patches`). tests/preview/picture_cli_test.cpp is the small version CI runs.
#
#   bench/picture.sh GIBAKE [OUTDIR]      env: SPP (reference samples a pixel, default 1024),
#                                         EXTRA_BAKE_ARGS, VIEWS (names below, default all)
# Prints one line a view: blocks within 10%, p10 / median / p90, the reference's own noise (the
# share of blocks a bake equal to the truth would score), then the check's figures, and the
# bake's wall and user seconds and file size. Minutes on 2 cores (the Sponza references dominate).
# Each view's reference is rendered once into OUTDIR/refs/VIEW_SPP.exr and read back from there by
# later runs with the same OUTDIR (`preview --reference-image`): delete it after changing the
# scene, its lights or the renderer.
set -euo pipefail
G=${1:?usage: bench/picture.sh GIBAKE [OUTDIR]}
O=${2:-/tmp/gibake_picture}
SPP=${SPP:-1024}
HERE=$(cd "$(dirname "$0")/.." && pwd)
A=${GIBAKE_ASSETS_DIR:-$HERE/../shared/assets}
SPONZA="$A/sponza/Sponza.gltf --sun 0.3,-1,0.2:100000"
# A view: the scene with its bake arguments, then after "|" the preview's camera.
declare -A VIEW=(
  [court]="$SPONZA|--size 320x180"
  [arcade]="$SPONZA|--size 320x180 --camera 9,5,3.5,-9,3,-3.5,0,1,0 --fov 70"
  [nvpro]="$A/cornell-box-nvpro/cornellBox.gltf|--size 256x256"
  [sample]="$HERE/samples/cornell/cornell.gltf|--size 256x256"
  [two_rooms]="$HERE/tests/reference/two_rooms.gltf|--size 256x192 --camera -1.9,1.2,0.9,-0.3,0.7,-0.9,0,1,0 --fov 75"
)
VIEWS=${VIEWS:-court arcade nvpro sample two_rooms}
mkdir -p "$O"
declare -A BAKED=()
for v in $VIEWS; do
  key=${VIEW[$v]%%|*}; camera=${VIEW[$v]#*|}
  read -r -a scene <<< "$key"
  bake="$O/${v}.gibake"
  if [[ -n "${BAKED[$key]:-}" ]]; then
    bake=${BAKED[$key]}
  else
    # shellcheck disable=SC2086
    /usr/bin/time -f "%e %U" -o "$O/$v.time" "$G" "${scene[@]}" --ddgi ${EXTRA_BAKE_ARGS:-} --out "$bake" \
      > "$O/$v.bake.log" 2>&1
    BAKED[$key]=$bake
    read -r wall user < "$O/$v.time"
    echo "$v: bake ${wall} s wall, ${user} s user, $(( $(stat -c %s "$bake") / 1000000 )) MB"
  fi
  ref="$O/refs/${v}_${SPP}.exr"
  if [[ ! -f "$ref" ]]; then
    mkdir -p "$O/refs"
    # shellcheck disable=SC2086
    "$G" preview "${scene[@]}" $camera --reference --spp "$SPP" --out "$ref" > "$O/$v.ref.log" 2>&1
  fi
  # shellcheck disable=SC2086
  "$G" preview "${scene[@]}" --bake "$bake" $camera --reference-image "$ref" --diff "$O/$v.diff.png" \
    --check-patches 256 --check-rays 512 --out "$O/$v.lit.png" > "$O/$v.view.log" 2>&1
  echo "$v: $(grep '8x8 blocks' "$O/$v.view.log")"
  echo "$v: $(grep 'reference noise (from' "$O/$v.view.log" | sed 's/; a bake equal.*//')"
  echo "$v: $(grep 'reconstruction error (camera' "$O/$v.view.log" | sed 's/ of the path-traced truth//')"
done
