#!/usr/bin/env python3
"""Writes the scenes of the Cycles reference tests (tests/reference), their probe grids and views.

For each scene NAME this writes, into the output directory:
  NAME.gltf         the scene, one file, its buffer embedded as a base64 data: URI
  NAME.probes.json  the explicit probe grid that `gibake bake --grid-min/--grid-max/--probe-counts
                    --relocate off` reproduces exactly (probe index = x + X*(y + Y*z),
                    position = grid_min + (x,y,z)*spacing), every position listed, and for each
                    probe whether it lies inside a closed solid of the scene (analytic, from the
                    shapes below; the reference test demands that those probes be inactive)

Scenes (glTF conventions: +Y up, metres; every material double-sided, albedo = baseColorFactor,
emitted radiance = emissiveFactor x KHR_materials_emissive_strength in cd/m2; no point or spot
lights, whose conversion to Blender's Watts is a trap):

  cornell_blocks  a 2 m Cornell-style box open at +Z (white floor, ceiling and back wall, red -X
                  wall, green +X wall), two blocks standing on the floor WITHOUT bottom faces
                  (closed only together with the floor; their sides reach 1 cm below the floor so
                  the seam is sealed), rotated about Y; an emissive patch set into a hole of the
                  ceiling (its back looks out of the box, into the black world). 4x4x4 probes,
                  three of them inside the blocks, the outer ones 10 cm from floor, ceiling and
                  walls, the front row in the open front's plane region.
  two_rooms       two closed rooms side by side sharing a 0.2 m thick wall. The left room has
                  coloured walls, an emissive ceiling patch and a window in its front wall through
                  which a sun (KHR_lights_punctual directional, lux) shines onto the floor and the
                  shared wall; the right room is closed and dark (the truth there is exactly 0).
                  Shell faces overlap at the edges by 1 cm so no ray slips through a seam.
                  5x3x2 probes: three columns in the lit room, one inside the shared wall, one in the dark room.
  lattice_court   an open-topped court with a checker-textured floor and a lattice screen whose
                  texture's alpha cuts square holes (alphaMode MASK), lit by a sun and a constant
                  sky; camera views only (no probe grid). Textures are PNGs in data: URIs.

views.json lists a camera view of each scene (eye, target, field of view, size, sky) for the
picture reference (scripts/cycles_reference.py --view; tests/reference/picture_reference_test.cpp).

Python 3 standard library only; the output is deterministic.

Usage: python3 tests/reference/make_scenes.py [output-directory]   (default: tests/reference)
"""
import base64
import json
import os
import struct
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts"))
from gltf_quads import Primitive, Writer, cross, dot, look_rotation, sub, y_rotation  # noqa: E402,F401


def material(name, color, emissive=None):
    m = {"name": name, "doubleSided": True,
         "pbrMetallicRoughness": {"baseColorFactor": list(color) + [1.0], "metallicFactor": 0.0,
                                  "roughnessFactor": 1.0}}
    if emissive:
        factor, strength = emissive
        m["emissiveFactor"] = list(factor)
        m["extensions"] = {"KHR_materials_emissive_strength": {"emissiveStrength": strength}}
    return m


def rotate_y(p, quat):
    """Rotates p by a unit quaternion about Y only, [0, s, 0, c] (glTF order x, y, z, w)."""
    s, c = quat[1], quat[3]
    cos_t, sin_t = c * c - s * s, 2.0 * s * c
    return [cos_t * p[0] + sin_t * p[2], p[1], -sin_t * p[0] + cos_t * p[2]]


def open_box_primitive(sink=0.01):
    """Unit block x,z in [-0.5, 0.5], y in [-sink, 1]: four sides and a top, NO bottom face."""
    p = Primitive()
    lo, hi = -0.5, 0.5
    for axis, sign in ((0, -1), (0, 1), (2, -1), (2, 1)):
        value = lo if sign < 0 else hi
        if axis == 0:  # plane x = value; other axes (y, z)
            p.rect(0, value, (-sink, lo), (1.0, hi), sign)
        else:  # plane z = value; other axes (x, y)
            p.rect(2, value, (lo, -sink), (hi, 1.0), sign)
    p.rect(1, 1.0, (lo, lo), (hi, hi), 1)  # top: plane y = 1; other axes (z, x)
    return p


class Block:
    """A block node: the unit open box scaled (sx, sy, sz), rotated about Y, translated."""

    def __init__(self, name, center_xz, size, degrees):
        self.name = name
        self.translation = [center_xz[0], 0.0, center_xz[1]]
        self.scale = list(size)
        self.rotation = y_rotation(degrees)

    def node(self, mesh):
        return {"name": self.name, "mesh": mesh, "translation": self.translation,
                "rotation": self.rotation, "scale": self.scale}

    def contains(self, p, margin=0.02):
        """p strictly inside (by margin) the solid the block closes together with the floor."""
        q = sub(p, self.translation)
        inv = [0.0, -self.rotation[1], 0.0, self.rotation[3]]
        q = rotate_y(q, inv)
        return (abs(q[0]) < self.scale[0] * 0.5 - margin and abs(q[2]) < self.scale[2] * 0.5 - margin
                and margin < q[1] < self.scale[1] - margin)


def grid_positions(grid_min, grid_max, counts):
    spacing = [(grid_max[i] - grid_min[i]) / (counts[i] - 1) if counts[i] > 1 else 0.0
               for i in range(3)]
    out = []
    for z in range(counts[2]):
        for y in range(counts[1]):
            for x in range(counts[0]):
                out.append([grid_min[0] + x * spacing[0], grid_min[1] + y * spacing[1],
                            grid_min[2] + z * spacing[2]])
    return out


def finish(name, w, meshes, nodes, materials, extensions=None, lights=None):
    gltf = {
        "asset": {"version": "2.0", "generator": "gibake tests/reference/make_scenes.py"},
        "scene": 0,
        "scenes": [{"name": name, "nodes": list(range(len(nodes)))}],
        "nodes": nodes,
        "meshes": meshes,
        "materials": materials,
        "accessors": w.accessors,
        "bufferViews": w.views,
        "buffers": [{"uri": "data:application/octet-stream;base64," +
                     base64.b64encode(bytes(w.blob)).decode("ascii"),
                     "byteLength": len(w.blob)}],
    }
    used = set(extensions or [])
    if lights:
        gltf["extensions"] = {"KHR_lights_punctual": {"lights": lights}}
        used.add("KHR_lights_punctual")
    if used:
        gltf["extensionsUsed"] = sorted(used)
    return gltf


def png_bytes(width, height, rows, channels):
    """An 8-bit PNG (colour type 2: RGB, 6: RGBA) of `rows` (lists of byte values), no filter."""
    import zlib

    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)
    raw = b"".join(b"\x00" + bytes(row) for row in rows)
    header = struct.pack(">IIBBBBB", width, height, 8, 2 if channels == 3 else 6, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw, 9)) +
            chunk(b"IEND", b""))


def srgb_byte(linear):
    c = linear * 12.92 if linear <= 0.0031308 else 1.055 * linear ** (1.0 / 2.4) - 0.055
    return max(0, min(255, int(round(c * 255.0))))


def textured_material(name, texture, alpha_cutoff=None):
    m = {"name": name, "doubleSided": True,
         "pbrMetallicRoughness": {"baseColorTexture": {"index": texture}, "metallicFactor": 0.0,
                                  "roughnessFactor": 1.0}}
    if alpha_cutoff is not None:
        m["alphaMode"] = "MASK"
        m["alphaCutoff"] = alpha_cutoff
    return m


# ---------------------------------------------------------------- scene 1: cornell_blocks

CB_PATCH = (0.3, 0.25)  # emissive patch half sizes in x and z, set into the ceiling
CB_EMISSION = ([1.0, 0.9, 0.8], 12.0)  # emissiveFactor, strength: cd/m2 = factor * strength
CB_BLOCKS = [Block("short_block", (0.35, 0.3), (0.6, 0.6, 0.6), -17.0),
             Block("tall_block", (-0.33, -0.3), (0.6, 1.2, 0.6), 17.0)]
CB_GRID = {"grid_min": [-0.9, 0.1, -0.9], "grid_max": [0.9, 1.9, 0.9], "counts": [4, 4, 4]}


def cornell_blocks():
    w = Writer()
    r, h = 1.0, 2.0
    px, pz = CB_PATCH
    white = Primitive()
    white.rect(1, 0.0, (-r, -r), (r, r), 1)  # floor: plane y = 0, axes (z, x)
    # ceiling with a hole for the patch: four rectangles around it
    white.rect(1, h, (-r, -r), (-pz, r), -1)
    white.rect(1, h, (pz, -r), (r, r), -1)
    white.rect(1, h, (-pz, -r), (pz, -px), -1)
    white.rect(1, h, (-pz, px), (pz, r), -1)
    white.rect(2, -r, (-r, 0.0), (r, h), 1)  # back wall: plane z = -1, axes (x, y)
    red = Primitive().rect(0, -r, (0.0, -r), (h, r), 1)  # plane x = -1, axes (y, z)
    green = Primitive().rect(0, r, (0.0, -r), (h, r), -1)
    patch = Primitive().rect(1, h, (-pz, -px), (pz, px), -1)
    block_white = open_box_primitive()
    materials = [material("cb_white", [0.75, 0.75, 0.75]), material("cb_red", [0.63, 0.065, 0.05]),
                 material("cb_green", [0.14, 0.45, 0.091]),
                 material("cb_light", [0.8, 0.8, 0.8], emissive=CB_EMISSION),
                 material("cb_block", [0.7, 0.68, 0.6])]
    meshes = [
        {"name": "room", "primitives": [w.primitive(white, 0), w.primitive(red, 1),
                                        w.primitive(green, 2)]},
        {"name": "light_patch", "primitives": [w.primitive(patch, 3)]},
        {"name": "open_block", "primitives": [w.primitive(block_white, 4)]},
    ]
    nodes = [{"name": "room", "mesh": 0}, {"name": "light_patch", "mesh": 1}]
    nodes += [b.node(2) for b in CB_BLOCKS]
    gltf = finish("cornell_blocks", w, meshes, nodes, materials,
                  extensions=["KHR_materials_emissive_strength"])
    return gltf, CB_GRID, CB_BLOCKS


# ---------------------------------------------------------------- scene 2: two_rooms

TR_X = 2.1  # outer half width; the rooms are x in [-2.1, -0.1] and [0.1, 2.1]
TR_WALL = 0.1  # half thickness of the shared wall
TR_H = 2.0
TR_Z = 1.0
TR_WINDOW = {"x": (-1.6, -0.7), "y": (0.8, 1.6)}  # hole in the left room's front wall (z = +1)
TR_PATCH = {"x": (-1.4, -0.8), "z": (-0.5, 0.1)}
TR_EMISSION = ([1.0, 1.0, 1.0], 20.0)
TR_SUN_DIR = [0.3, -0.6, -0.75]  # direction the light travels (glTF: the node's -Z)
TR_SUN_LUX = 30.0
TR_SUN_COLOR = [1.0, 0.95, 0.85]
TR_GRID = {"grid_min": [-1.8, 0.2, -0.6], "grid_max": [0.6, 1.8, 0.6], "counts": [5, 3, 2]}


def two_rooms():
    w = Writer()
    e = 0.01  # overlap at the shell's edges
    X, H, Z, T = TR_X, TR_H, TR_Z, TR_WALL
    floor = Primitive().rect(1, 0.0, (-Z - e, -X - e), (Z + e, X + e), 1)
    ceiling = Primitive()
    pz, px = TR_PATCH["z"], TR_PATCH["x"]
    # ceiling (plane y = H, axes (z, x)) around the patch hole
    ceiling.rect(1, H, (-Z - e, -X - e), (pz[0], X + e), -1)
    ceiling.rect(1, H, (pz[1], -X - e), (Z + e, X + e), -1)
    ceiling.rect(1, H, (pz[0], -X - e), (pz[1], px[0]), -1)
    ceiling.rect(1, H, (pz[0], px[1]), (pz[1], X + e), -1)
    patch = Primitive().rect(1, H, (pz[0], px[0]), (pz[1], px[1]), -1)
    back = Primitive().rect(2, -Z, (-X - e, -e), (X + e, H + e), 1)  # plane z = -Z, axes (x, y)
    front = Primitive()  # plane z = +Z with the window in the left room
    wx, wy = TR_WINDOW["x"], TR_WINDOW["y"]
    front.rect(2, Z, (-X - e, -e), (wx[0], H + e), -1)
    front.rect(2, Z, (wx[1], -e), (X + e, H + e), -1)
    front.rect(2, Z, (wx[0], -e), (wx[1], wy[0]), -1)
    front.rect(2, Z, (wx[0], wy[1]), (wx[1], H + e), -1)
    left = Primitive().rect(0, -X, (-e, -Z - e), (H + e, Z + e), 1)  # plane x, axes (y, z)
    right = Primitive().rect(0, X, (-e, -Z - e), (H + e, Z + e), -1)
    shared = Primitive()
    shared.rect(0, -T, (-e, -Z - e), (H + e, Z + e), -1)  # faces the left room
    shared.rect(0, T, (-e, -Z - e), (H + e, Z + e), 1)  # faces the right room
    materials = [material("tr_floor", [0.55, 0.5, 0.45]), material("tr_ceiling", [0.8, 0.8, 0.8]),
                 material("tr_back", [0.2, 0.35, 0.7]), material("tr_front", [0.7, 0.7, 0.65]),
                 material("tr_left", [0.75, 0.3, 0.2]), material("tr_right", [0.3, 0.6, 0.3]),
                 material("tr_shared", [0.6, 0.6, 0.2]),
                 material("tr_light", [0.8, 0.8, 0.8], emissive=TR_EMISSION)]
    prims = [floor, ceiling, back, front, left, right, shared]
    meshes = [{"name": "shell", "primitives": [w.primitive(p, i) for i, p in enumerate(prims)]},
              {"name": "light_patch", "primitives": [w.primitive(patch, 7)]}]
    nodes = [{"name": "shell", "mesh": 0}, {"name": "light_patch", "mesh": 1},
             {"name": "sun", "rotation": look_rotation(TR_SUN_DIR),
              "extensions": {"KHR_lights_punctual": {"light": 0}}}]
    lights = [{"name": "sun", "type": "directional", "color": TR_SUN_COLOR,
               "intensity": TR_SUN_LUX}]
    gltf = finish("two_rooms", w, meshes, nodes, materials,
                  extensions=["KHR_materials_emissive_strength"], lights=lights)

    class Wall:
        def contains(self, p, margin=0.02):
            return abs(p[0]) < T - margin and margin < p[1] < H - margin and abs(p[2]) < Z - margin

    return gltf, TR_GRID, [Wall()]


# ---------------------------------------------------------------- scene 3: lattice_court

LC_HALF = 3.0  # floor x, z in [-3, 3]
LC_H = 3.0  # wall height; the front (+Z) and the top are open
LC_SCREEN = {"x": (-1.5, 1.5), "y": (0.0, 2.5), "z": -0.8}
LC_SUN_DIR = [0.35, -0.7, -0.6]
LC_SUN_LUX = 20.0
LC_SUN_COLOR = [1.0, 0.96, 0.9]
LC_CHECKER = (0.7, 0.12)  # linear albedos of the floor's light and dark squares
LC_BARS = (0.8, 0.62, 0.4)  # linear albedo of the lattice's bars


def checker_png(size=8):
    rows = []
    for j in range(size):
        row = []
        for i in range(size):
            a = LC_CHECKER[0] if (i // 2 + j // 2) % 2 == 0 else LC_CHECKER[1]
            row += [srgb_byte(a)] * 3
        rows.append(row)
    return png_bytes(size, size, rows, 3)


def lattice_png(size=16, period=8, bar=3):
    """Bars `bar` texels wide every `period` texels, opaque; the square holes between, alpha 0."""
    rows = []
    colour = [srgb_byte(c) for c in LC_BARS]
    for j in range(size):
        row = []
        for i in range(size):
            opaque = i % period < bar or j % period < bar
            row += colour + [255 if opaque else 0]
        rows.append(row)
    return png_bytes(size, size, rows, 4)


def lattice_court():
    """An open-topped court: a checker-textured floor, three plain walls, and a lattice screen
    (alphaMode MASK: bars opaque, square holes alpha 0) standing in it, lit by a sun and a
    constant sky (LC_SKY, given to both renderers as --sky) through the open top and front."""
    w = Writer()
    r, h = LC_HALF, LC_H
    floor = Primitive(uv_metres=1.0).rect(1, 0.0, (-r, -r), (r, r), 1)
    back = Primitive().rect(2, -r, (-r, 0.0), (r, h), 1)
    left = Primitive().rect(0, -r, (0.0, -r), (h, r), 1)
    right = Primitive().rect(0, r, (0.0, -r), (h, r), -1)
    sx, sy = LC_SCREEN["x"], LC_SCREEN["y"]
    screen = Primitive(uv_metres=1.25).rect(2, LC_SCREEN["z"], (sx[0], sy[0]), (sx[1], sy[1]), 1)
    images = [checker_png(), lattice_png()]
    materials = [textured_material("lc_floor", 0), material("lc_back", [0.7, 0.7, 0.68]),
                 material("lc_left", [0.6, 0.3, 0.25]), material("lc_right", [0.3, 0.5, 0.6]),
                 textured_material("lc_screen", 1, alpha_cutoff=0.5)]
    prims = [floor, back, left, right, screen]
    meshes = [{"name": "court", "primitives": [w.primitive(p, i) for i, p in enumerate(prims)]}]
    nodes = [{"name": "court", "mesh": 0},
             {"name": "sun", "rotation": look_rotation(LC_SUN_DIR),
              "extensions": {"KHR_lights_punctual": {"light": 0}}}]
    lights = [{"name": "sun", "type": "directional", "color": LC_SUN_COLOR, "intensity": LC_SUN_LUX}]
    gltf = finish("lattice_court", w, meshes, nodes, materials, lights=lights)
    gltf["images"] = [{"uri": "data:image/png;base64," + base64.b64encode(png).decode("ascii")}
                      for png in images]
    gltf["textures"] = [{"source": 0}, {"source": 1}]
    return gltf


LC_SKY = [0.35, 0.45, 0.6]  # constant sky radiance, cd/m2

# Camera views of the three scenes for the picture reference (tests/reference/views.json):
# eye, target (glTF world, +Y up), vertical field of view in degrees, image size, and the lighting
# options both renderers are given beyond the scene's own lights.
VIEWS = [
    {"name": "cornell_blocks", "scene": "cornell_blocks.gltf", "eye": [0.0, 1.0, 3.4],
     "target": [0.0, 0.95, 0.0], "fov": 45.0, "width": 128, "height": 96, "sky": [0.0, 0.0, 0.0]},
    {"name": "two_rooms", "scene": "two_rooms.gltf", "eye": [-0.25, 1.5, 0.85],
     "target": [-1.7, 0.6, -0.8], "fov": 70.0, "width": 128, "height": 96, "sky": [0.0, 0.0, 0.0]},
    {"name": "lattice_court", "scene": "lattice_court.gltf", "eye": [0.4, 1.7, 5.2],
     "target": [0.0, 0.9, -1.5], "fov": 55.0, "width": 128, "height": 96, "sky": LC_SKY},
]


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    out_dir = sys.argv[1] if len(sys.argv) > 1 else here
    os.makedirs(out_dir, exist_ok=True)
    for name, make in (("cornell_blocks", cornell_blocks), ("two_rooms", two_rooms)):
        gltf, grid, solids = make()
        with open(os.path.join(out_dir, name + ".gltf"), "w", encoding="utf-8") as f:
            json.dump(gltf, f, indent=1)
            f.write("\n")
        positions = grid_positions(grid["grid_min"], grid["grid_max"], grid["counts"])
        probes = [{"index": i, "position": [round(c, 6) for c in p],
                   "inside_solid": any(s.contains(p) for s in solids)}
                  for i, p in enumerate(positions)]
        doc = {"scene": name + ".gltf", "grid_min": grid["grid_min"], "grid_max": grid["grid_max"],
               "counts": grid["counts"],
               "gibake_grid_args": ["--grid-min", ",".join(repr(v) for v in grid["grid_min"]),
                                    "--grid-max", ",".join(repr(v) for v in grid["grid_max"]),
                                    "--probe-counts", ",".join(str(v) for v in grid["counts"]),
                                    "--relocate", "off"],
               "probes": probes}
        with open(os.path.join(out_dir, name + ".probes.json"), "w", encoding="utf-8") as f:
            json.dump(doc, f, indent=1)
            f.write("\n")
        inside = sum(p["inside_solid"] for p in probes)
        print("%s: %d probes, %d inside solids" % (name, len(probes), inside))
    with open(os.path.join(out_dir, "lattice_court.gltf"), "w", encoding="utf-8") as f:
        json.dump(lattice_court(), f, indent=1)
        f.write("\n")
    with open(os.path.join(out_dir, "views.json"), "w", encoding="utf-8") as f:
        json.dump({"views": VIEWS}, f, indent=1)
        f.write("\n")
    print("lattice_court, views.json: %d views" % len(VIEWS))


if __name__ == "__main__":
    main()
