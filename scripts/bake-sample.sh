#!/usr/bin/env bash
# Installs dependencies, builds gibake (Release) and bakes the bundled sample scene.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build -j "$(nproc)" --target gibake
mkdir -p out
build/cli/gibake samples/cornell/cornell.gltf --ddgi --out out/cornell.gibake "$@"
build/cli/gibake info out/cornell.gibake
