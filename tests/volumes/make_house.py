#!/usr/bin/env python3
"""Writes tests/volumes/house_on_ground.gltf: a house standing on a ground plane 20 times its size,
lit by a sun (issue 19's "building on a large ground plane", the automatic detail volume's test).

The house (glTF conventions: +Y up, metres) is 8 m x 3.2 m x 6 m (x in [-4, 4], z in [-3, 3]) on the
ground plane y = 0, which spans x, z in [-80, 80]. Walls 0.2 m thick (closed boxes), a 0.2 m roof
slab on top, two rooms split by an inner wall at x = 0 with a door (z in [-0.5, 0.5], up to 2.1 m);
the left room has a door in its front wall (z = +3, x in [-2.6, -1.6], up to 2.1 m), the right
room a window (x in [1.4, 2.8], y in [1.0, 2.1]). A sun travels (0.35, -0.55, -0.76): from the
front, through the door and the window onto the floors. Every material double-sided.

Python 3 standard library only; the output is deterministic.
Usage: python3 tests/volumes/make_house.py [output.gltf]
"""
import base64
import json
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts"))
from gltf_quads import Primitive, Writer, look_rotation  # noqa: E402

GROUND = 80.0
SUN_DIR = [0.35, -0.55, -0.76]
SUN_LUX = 50000.0


def material(name, color):
    return {"name": name, "doubleSided": True,
            "pbrMetallicRoughness": {"baseColorFactor": list(color) + [1.0], "metallicFactor": 0.0,
                                     "roughnessFactor": 1.0}}


def box(prim, lo, hi):
    """A closed axis-aligned box, faces outward."""
    for axis in range(3):
        u, v = (axis + 1) % 3, (axis + 2) % 3
        prim.rect(axis, lo[axis], (lo[u], lo[v]), (hi[u], hi[v]), -1)
        prim.rect(axis, hi[axis], (lo[u], lo[v]), (hi[u], hi[v]), 1)


def wall(prim, along, a0, a1, t0, t1, holes, height=3.0):
    """A wall along axis `along` (0: x, 2: z) from a0 to a1, t0..t1 thick across it, with rectangular
    holes (aa, ab, ya, yb): from aa to ab along it, ya to yb up."""
    def part(a_lo, a_hi, y_lo, y_hi):
        lo, hi = [t0, y_lo, t0], [t1, y_hi, t1]
        lo[along], hi[along] = a_lo, a_hi
        box(prim, lo, hi)
    a = a0
    for aa, ab, ya, yb in sorted(holes):
        part(a, aa, 0.0, height)
        if ya > 0.0:
            part(aa, ab, 0.0, ya)
        part(aa, ab, yb, height)
        a = ab
    part(a, a1, 0.0, height)


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                                             "house_on_ground.gltf")
    w = Writer()
    ground = Primitive().rect(1, 0.0, (-GROUND, -GROUND), (GROUND, GROUND), 1)
    walls = Primitive()
    wall(walls, 0, -4.0, 4.0, -3.0, -2.8, [])                                            # back
    wall(walls, 0, -4.0, 4.0, 2.8, 3.0, [(-2.6, -1.6, 0.0, 2.1), (1.4, 2.8, 1.0, 2.1)])  # front
    wall(walls, 2, -2.8, 2.8, -4.0, -3.8, [])                                            # left
    wall(walls, 2, -2.8, 2.8, 3.8, 4.0, [])                                              # right
    wall(walls, 2, -2.8, 2.8, -0.1, 0.1, [(-0.5, 0.5, 0.0, 2.1)])                       # inner, door
    roof = Primitive()
    box(roof, [-4.0, 3.0, -3.0], [4.0, 3.2, 3.0])
    materials = [material("ground", [0.45, 0.45, 0.42]), material("walls", [0.75, 0.72, 0.68]),
                 material("roof", [0.5, 0.3, 0.25])]
    meshes = [{"name": "ground", "primitives": [w.primitive(ground, 0)]},
              {"name": "walls", "primitives": [w.primitive(walls, 1)]},
              {"name": "roof", "primitives": [w.primitive(roof, 2)]}]
    nodes = [{"name": "ground", "mesh": 0}, {"name": "walls", "mesh": 1}, {"name": "roof", "mesh": 2},
             {"name": "sun", "rotation": look_rotation(SUN_DIR), "extensions": {"KHR_lights_punctual": {"light": 0}}}]
    gltf = {
        "asset": {"version": "2.0", "generator": "gibake tests/volumes/make_house.py"},
        "scene": 0,
        "scenes": [{"name": "house_on_ground", "nodes": list(range(len(nodes)))}],
        "nodes": nodes, "meshes": meshes, "materials": materials,
        "accessors": w.accessors, "bufferViews": w.views,
        "buffers": [{"uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(w.blob)).decode("ascii"),
                     "byteLength": len(w.blob)}],
        "extensions": {"KHR_lights_punctual": {"lights": [{"name": "sun", "type": "directional",
                                                           "color": [1.0, 0.96, 0.9], "intensity": SUN_LUX}]}},
        "extensionsUsed": ["KHR_lights_punctual"],
    }
    with open(out, "w", encoding="utf-8") as f:
        json.dump(gltf, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
