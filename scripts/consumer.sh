#!/usr/bin/env bash
# Installs the Release build into build/install, then configures, builds and runs
# samples/consumer against that install tree (find_package(gibake), gibake_bake(), loader, and
# with glslc fragment shaders including the installed gibake/ddgi_sample.glsl and gibake/vxgi_cone.glsl).
set -euo pipefail
cd "$(dirname "$0")/.."
prefix="$PWD/build/install"
cmake --install build --prefix "$prefix" >/dev/null
rm -rf build/consumer
cmake -S samples/consumer -B build/consumer -G Ninja -DCMAKE_PREFIX_PATH="$prefix"
cmake --build build/consumer
build/consumer/consumer build/consumer/cornell.gibake
# A second build must not re-bake: the depfile says nothing changed.
if cmake --build build/consumer -- -n -d explain 2>&1 | grep -q "gibake: baking"; then
  echo "consumer.sh: rebuild would re-bake although no input changed" >&2
  exit 1
fi
# The installed gibake loads the installed OpenVDB module (io/vdb/vdb_module.h), not the build tree's.
LD_DEBUG=files "$prefix/bin/gibake" samples/cornell/cornell.gltf --voxels build/consumer/cornell.vdb \
  --voxel-res 24 2>build/consumer/voxels.log
if ! grep -q "file=$prefix/.*/libgibake_openvdb.so .*dynamically loaded" build/consumer/voxels.log; then
  echo "consumer.sh: the installed gibake did not load the installed OpenVDB module:" >&2
  grep "libgibake_openvdb" build/consumer/voxels.log >&2 || true
  exit 1
fi
echo "consumer.sh: ok"
