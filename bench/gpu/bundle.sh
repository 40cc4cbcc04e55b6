#!/usr/bin/env bash
# Packs what an end-to-end bake needs on a GPU machine that has no package registry: the gibake
# binary with the Debian libraries it links (glibc, the Vulkan loader and GLVND excluded), Debian's
# Vulkan loader and GLVND packages as .debs, a setup script, and Sponza with only the images the
# baker reads (base colour; the normal and roughness maps point at one small image: a bake of that
# copy verifies identical to the original at tolerance 0).
#   bench/gpu/bundle.sh <gibake binary> <sponza dir> <out dir>
# On the GPU machine:
#   tar -xJf OUT/gb.tar.xz -C /tmp && tar -xJf OUT/sponza.tar.xz -C /tmp && /tmp/gb/setup-device.sh
#   export LD_LIBRARY_PATH=/tmp/gb/lib VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
#   /tmp/gb/gibake /tmp/sponza/Sponza.gltf --ddgi ... --backend vulkan
# NVIDIA's ICD (libGLX_nvidia) resolves the loader and GLVND from the system's library path: a
# loader in LD_LIBRARY_PATH beside it fails with "Could not get 'vkCreateInstance' via
# 'vk_icdGetInstanceProcAddr'", so the packages are unpacked into / and ldconfig'd there instead.
set -euo pipefail
exe=$1 sponza=$2 out=$3
mkdir -p "$out"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

mkdir -p "$work/gb/lib"
cp "$exe" "$work/gb/gibake"
# The OpenVDB module (io/vdb/vdb_module.h), beside the binary where gibake looks for it.
module=$(dirname "$exe")/../lib/gibake/libgibake_openvdb.so
cp "$module" "$work/gb/"
ldd "$exe" "$module" | awk '/=> \// {print $3}' | sort -u |
  grep -vE '/(libc|libm|libpthread|libdl|librt|ld-linux[^/]*|libvulkan|libGLdispatch)\.so' |
  while read -r lib; do cp -L "$lib" "$work/gb/lib/"; done
# The Vulkan loader and the GLVND pieces NVIDIA's ICD expects, installed into / on the device.
mkdir -p "$work/gb/debs"
(cd "$work/gb/debs" && apt-get download libvulkan1 libglvnd0 libegl1 libgl1 libglx0 libopengl0 libgles2 >/dev/null)
cat >"$work/gb/setup-device.sh" <<'SETUP'
#!/usr/bin/env bash
# Unpacks the Vulkan loader and GLVND into / (the device machine has no package registry) and
# refreshes the linker cache; the bundle's lib/ holds neither, so the system's are the ones found.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
for deb in "$here"/debs/*.deb; do dpkg -x "$deb" /; done
ldconfig
rm -f "$here"/lib/libvulkan* "$here"/lib/libGLdispatch*
SETUP
chmod +x "$work/gb/setup-device.sh"
tar -C "$work" -cf - gb | xz -9e -T2 >"$out/gb.tar.xz"

mkdir -p "$work/sponza"
python3 - "$sponza" "$work/sponza" <<'EOF'
import json, os, shutil, sys
src, dst = sys.argv[1], sys.argv[2]
g = json.load(open(os.path.join(src, 'Sponza.gltf')))
read = set()
for m in g.get('materials', []):
    for ref in (m.get('pbrMetallicRoughness', {}).get('baseColorTexture'), m.get('emissiveTexture')):
        if ref: read.add(g['textures'][ref['index']]['source'])
small = min((i for i in range(len(g['images'])) if i in read),
            key=lambda i: os.path.getsize(os.path.join(src, g['images'][i]['uri'])))
for i, im in enumerate(g['images']):
    if i not in read: im['uri'] = g['images'][small]['uri']
for i in read | {small}: shutil.copy(os.path.join(src, g['images'][i]['uri']), dst)
for b in g['buffers']: shutil.copy(os.path.join(src, b['uri']), dst)
json.dump(g, open(os.path.join(dst, 'Sponza.gltf'), 'w'))
EOF
# xz: the bundle (18 + 43 MB) and the repository must fit the device tool's 64 MiB together.
tar -C "$work" -cf - sponza | xz -6 -T2 >"$out/sponza.tar.xz"
du -sh "$out"/*
