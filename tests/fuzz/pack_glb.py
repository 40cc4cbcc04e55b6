#!/usr/bin/env python3
"""Packs a .gltf with external buffers and images into one self-contained .glb (one BIN chunk), so
that a fuzz seed reaches Draco and image decoding from a single input. Usage: pack_glb.py in.gltf out.glb"""
import base64
import json
import os
import struct
import sys


def pack(src, dst):
    base = os.path.dirname(src)
    doc = json.load(open(src))
    blob = bytearray()
    offsets = []
    for b in doc.get("buffers", []):
        uri = b["uri"]
        data = base64.b64decode(uri.split(",", 1)[1]) if uri.startswith("data:") else open(os.path.join(base, uri), "rb").read()
        while len(blob) % 4:
            blob.append(0)
        offsets.append(len(blob))
        blob += data
        del b["uri"]
    for v in doc.get("bufferViews", []):
        v["byteOffset"] = v.get("byteOffset", 0) + offsets[v.get("buffer", 0)]
        v["buffer"] = 0
    views = doc.setdefault("bufferViews", [])
    for im in doc.get("images", []):
        uri = im.get("uri", "")
        if not uri or uri.startswith("data:"):
            continue
        data = open(os.path.join(base, uri), "rb").read()
        while len(blob) % 4:
            blob.append(0)
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data)})
        blob += data
        im["bufferView"] = len(views) - 1
        im["mimeType"] = "image/png" if uri.lower().endswith(".png") else "image/jpeg"
        del im["uri"]
    while len(blob) % 4:
        blob.append(0)
    doc["buffers"] = [{"byteLength": len(blob)}]
    text = json.dumps(doc, separators=(",", ":")).encode()
    while len(text) % 4:
        text += b" "
    out = struct.pack("<4sII", b"glTF", 2, 12 + 8 + len(text) + 8 + len(blob))
    out += struct.pack("<I4s", len(text), b"JSON") + text + struct.pack("<I4s", len(blob), b"BIN\0") + bytes(blob)
    open(dst, "wb").write(out)


if __name__ == "__main__":
    pack(sys.argv[1], sys.argv[2])
