#!/usr/bin/env python3
"""Writes samples/cornell/cornell.gltf + cornell.bin: gibake's bundled sample scene.

A Cornell-box-like room, 2 m on a side (+Y up, metres, glTF conventions): white floor, ceiling
and back wall, red left wall (-X), green right wall (+X), open front (+Z); two white boxes
placed by node transforms (one mesh, two instances; they float 1 mm above the floor so that
no two faces are coplanar and the mesh diagnostics stay clean); a small emissive panel under the ceiling
(emissiveFactor 1 x KHR_materials_emissive_strength 10 = 10 cd/m2); one KHR_lights_punctual
point light (candela); a camera looking in through the open side.

Every surface faces the side it is meant to be seen from: the room's walls face into the room,
the boxes face outwards, the panel faces down. Triangles wind counter-clockwise seen from the
front (the script checks each one against its normal). Python 3 standard library only; the
output is deterministic.

Usage: python3 samples/make_sample_scene.py [output-directory]   (default: samples/cornell)
"""
import json
import math
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scripts"))
from gltf_quads import Primitive, Writer, y_rotation  # noqa: E402

ROOM = 1.0  # half extent in x and z; the room spans y in [0, 2 * ROOM]
PANEL_HALF = (0.25, 0.20)  # emissive panel half sizes in x and z
PANEL_Y = 2.0 * ROOM - 0.01
EMISSIVE_STRENGTH = 10.0  # cd/m2 with emissiveFactor 1
BULB_CANDELA = 3.0
BULB_POSITION = [0.0, 1.5, 0.3]

WHITE = [0.75, 0.75, 0.75, 1.0]
RED = [0.63, 0.065, 0.05, 1.0]
GREEN = [0.14, 0.45, 0.091, 1.0]


def room_primitives():
    r, h = ROOM, 2.0 * ROOM
    white = Primitive()
    white.quad([[-r, 0, -r], [r, 0, -r], [r, 0, r], [-r, 0, r]], [0, 1, 0])  # floor
    white.quad([[-r, h, -r], [r, h, -r], [r, h, r], [-r, h, r]], [0, -1, 0])  # ceiling
    white.quad([[-r, 0, -r], [r, 0, -r], [r, h, -r], [-r, h, -r]], [0, 0, 1])  # back wall
    red = Primitive().quad([[-r, 0, -r], [-r, 0, r], [-r, h, r], [-r, h, -r]], [1, 0, 0])
    green = Primitive().quad([[r, 0, -r], [r, 0, r], [r, h, r], [r, h, -r]], [-1, 0, 0])
    return [(white, 0), (red, 1), (green, 2)]


def panel_primitive():
    x, z = PANEL_HALF
    y = PANEL_Y
    return Primitive().quad([[-x, y, -z], [x, y, -z], [x, y, z], [-x, y, z]], [0, -1, 0])


def unit_cube_primitive():
    p = Primitive()
    for axis in range(3):
        for sign in (-0.5, 0.5):
            normal = [0.0, 0.0, 0.0]
            normal[axis] = 1.0 if sign > 0 else -1.0
            u, v = (axis + 1) % 3, (axis + 2) % 3
            corners = []
            for du, dv in ((-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)):
                c = [0.0, 0.0, 0.0]
                c[axis], c[u], c[v] = sign, du, dv
                corners.append(c)
            p.quad(corners, normal)
    return p


def material(name, color, emissive=False):
    m = {"name": name,
         "pbrMetallicRoughness": {"baseColorFactor": color, "metallicFactor": 0.0,
                                  "roughnessFactor": 1.0}}
    if emissive:
        m["emissiveFactor"] = [1.0, 1.0, 1.0]
        m["extensions"] = {"KHR_materials_emissive_strength":
                           {"emissiveStrength": EMISSIVE_STRENGTH}}
    return m


def build(bin_name):
    w = Writer(exact_bounds=False)
    meshes = [
        {"name": "room", "primitives": [w.primitive(p, m) for p, m in room_primitives()]},
        {"name": "light_panel", "primitives": [w.primitive(panel_primitive(), 3)]},
        {"name": "box", "primitives": [w.primitive(unit_cube_primitive(), 0)]},
    ]
    nodes = [
        {"name": "room", "mesh": 0},
        {"name": "light_panel", "mesh": 1},
        {"name": "short_box", "mesh": 2, "translation": [0.35, 0.301, 0.3],
         "rotation": y_rotation(-17.0), "scale": [0.6, 0.6, 0.6]},
        {"name": "tall_box", "mesh": 2, "translation": [-0.33, 0.601, -0.3],
         "rotation": y_rotation(17.0), "scale": [0.6, 1.2, 0.6]},
        {"name": "bulb", "translation": BULB_POSITION,
         "extensions": {"KHR_lights_punctual": {"light": 0}}},
        {"name": "camera", "translation": [0.0, 1.0, 3.8], "camera": 0},
    ]
    gltf = {
        "asset": {"version": "2.0", "generator": "gibake samples/make_sample_scene.py"},
        "extensionsUsed": ["KHR_lights_punctual", "KHR_materials_emissive_strength"],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"name": "bulb", "type": "point", "color": [1.0, 0.85, 0.7],
             "intensity": BULB_CANDELA}]}},
        "scene": 0,
        "scenes": [{"name": "cornell", "nodes": list(range(len(nodes)))}],
        "nodes": nodes,
        "meshes": meshes,
        "materials": [material("white", WHITE), material("red", RED),
                      material("green", GREEN), material("light", WHITE, emissive=True)],
        "cameras": [{"name": "front", "type": "perspective",
                     "perspective": {"yfov": 0.6, "aspectRatio": 1.0, "znear": 0.05,
                                     "zfar": 100.0}}],
        "accessors": w.accessors,
        "bufferViews": w.views,
        "buffers": [{"uri": bin_name, "byteLength": len(w.blob)}],
    }
    return gltf, bytes(w.blob)


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    out_dir = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "cornell")
    os.makedirs(out_dir, exist_ok=True)
    gltf, blob = build("cornell.bin")
    with open(os.path.join(out_dir, "cornell.bin"), "wb") as f:
        f.write(blob)
    with open(os.path.join(out_dir, "cornell.gltf"), "w", encoding="utf-8") as f:
        json.dump(gltf, f, indent=2)
        f.write("\n")
    triangles = sum(len(p.indices) for p, _ in room_primitives()) // 3 + 2 + 2 * 12
    print("wrote %s (%d bytes of buffer, %d triangles placed)" % (out_dir, len(blob), triangles))


if __name__ == "__main__":
    main()
