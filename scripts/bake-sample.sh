#!/usr/bin/env bash
# Installs dependencies, builds gibake (Release) and bakes the bundled sample scene.
set -euo pipefail
cd "$(dirname "$0")/.."
[ "${GIBAKE_SKIP_SETUP:-0}" = 1 ] || scripts/setup.sh  # GIBAKE_SKIP_SETUP=1: packages managed elsewhere
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build -j "$(nproc)" --target gibake
mkdir -p out
build/cli/gibake samples/cornell/cornell.gltf --ddgi --out out/cornell.gibake "$@"
build/cli/gibake info out/cornell.gibake
