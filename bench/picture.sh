#!/usr/bin/env bash
# The picture at full size: for each view, a bake (default settings plus EXTRA_BAKE_ARGS)
# rendered through the loader's sampler against a high-sample path-traced reference, 8x8-pixel
# blocks of luminance (`preview --diff`), beside the bake's own reconstruction check from the same
# camera (`--check-patches`). tests/preview/picture_cli_test.cpp is the small version CI runs.
#
#   bench/picture.sh GIBAKE [OUTDIR]      env: SPP (reference samples a pixel, default 4096),
#                                         EXTRA_BAKE_ARGS, VIEWS (names below, default all),
#                                         SEEDS (bake seeds, default "0"; several: each, then the mean)
# Beside each bake's lit view and --diff it writes OUTDIR/VIEW_sSEED.blocks.png (`preview --block-map`:
# the blocks outside 10%, red brighter, blue darker), and its log lists the farthest for --explain.
# Prints one line a view: blocks within 10%, p10 / median / p90, the reference's own noise (the
# share of blocks a bake equal to the truth would score), then the check's figures, and the
# bake's wall and user seconds and file size. A first run takes tens of minutes on 2 cores (the
# Sponza references dominate); later runs with the same OUTDIR only bake and compare.
# Each view's reference is rendered once into OUTDIR/refs/VIEW_SPP.exr and read back from there by
# later runs with the same OUTDIR (`preview --reference-image`): delete it after changing the
# scene, its lights or the renderer. 4,096 samples keep the references' own noise out of the
# figures (Sponza's arcade: 96% of blocks within 10% of the truth, 81% at 1,024).
set -euo pipefail
G=${1:?usage: bench/picture.sh GIBAKE [OUTDIR]}
O=${2:-/tmp/gibake_picture}
SPP=${SPP:-4096}
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
SEEDS=${SEEDS:-0}
mkdir -p "$O"
declare -A BAKED=()
for v in $VIEWS; do
  key=${VIEW[$v]%%|*}; camera=${VIEW[$v]#*|}
  read -r -a scene <<< "$key"
  ref="$O/refs/${v}_${SPP}.exr"
  if [[ ! -f "$ref" ]]; then
    mkdir -p "$O/refs"
    # shellcheck disable=SC2086
    "$G" preview "${scene[@]}" $camera --reference --spp "$SPP" --out "$ref" > "$O/$v.ref.log" 2>&1
  fi
  sum=0
  for seed in $SEEDS; do
    tag=$v; [[ "$SEEDS" == "0" ]] || tag="$v seed $seed"
    bake="$O/${v}_s${seed}.gibake"
    if [[ -n "${BAKED[$key|$seed]:-}" ]]; then
      bake=${BAKED[$key|$seed]}
    else
      # shellcheck disable=SC2086
      /usr/bin/time -f "%e %U" -o "$O/$v.time" "$G" "${scene[@]}" --ddgi --seed "$seed" ${EXTRA_BAKE_ARGS:-} \
        --out "$bake" > "$O/${v}_s${seed}.bake.log" 2>&1
      BAKED[$key|$seed]=$bake
      read -r wall user < "$O/$v.time"
      echo "$tag: bake ${wall} s wall, ${user} s user, $(( $(stat -c %s "$bake") / 1000000 )) MB"
    fi
    log="$O/${v}_s${seed}.view.log"
    # shellcheck disable=SC2086
    "$G" preview "${scene[@]}" --bake "$bake" $camera --reference-image "$ref" --diff "$O/${v}_s${seed}.diff.png" \
      --block-map "$O/${v}_s${seed}.blocks.png" --check-patches 256 --check-rays 2048 \
      --out "$O/${v}_s${seed}.lit.png" > "$log" 2>&1
    echo "$tag: $(grep '^8x8 blocks' "$log")"
    echo "$tag: $(grep '^worst 8x8 blocks' "$log" | sed 's/ (lit\/reference.*centre)//')"
    echo "$tag: $(grep 'reconstruction error (camera' "$log" | sed 's/ of the path-traced truth//')"
    sum=$(awk -v a="$sum" -v b="$(grep -o '[0-9.]*% of' "$log" | head -1 | tr -d '% of')" 'BEGIN { print a + b }')
  done
  echo "$v: $(grep 'reference noise (from' "$log" | sed 's/; a bake equal.*//')"
  n=$(wc -w <<< "$SEEDS")
  if (( n > 1 )); then
    echo "$v: blocks within 10%, mean over seeds $SEEDS: $(awk -v s="$sum" -v n="$n" 'BEGIN { printf "%.1f%%", s / n }')"
  fi
done
