"""Small glTF writing helpers shared by the scene generators (samples/make_sample_scene.py,
tests/reference/make_scenes.py): flat-shaded quads with checked winding, and a writer for one
binary buffer with its views and accessors. Python 3 standard library only; deterministic."""
import math
import struct


def sub(a, b):
    return [a[i] - b[i] for i in range(3)]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def dot(a, b):
    return sum(a[i] * b[i] for i in range(3))


class Primitive:
    """Flat-shaded quads: 4 vertices and 2 triangles each, wound CCW around `normal`."""

    def __init__(self, uv_metres=0.0):
        """uv_metres > 0: a TEXCOORD_0 too, planar: the rectangle's two in-plane world
        coordinates divided by uv_metres (one texture repeat every uv_metres metres)."""
        self.positions, self.normals, self.indices, self.uvs = [], [], [], []
        self.uv_metres = uv_metres

    def quad(self, corners, normal, uvs=None):
        base = len(self.positions)
        self.positions.extend([[float(c) for c in p] for p in corners])
        self.normals.extend([[float(c) for c in normal]] * 4)
        if uvs:
            self.uvs.extend([[float(c) for c in uv] for uv in uvs])
        for tri in ((0, 1, 2), (0, 2, 3)):
            a, b, c = (corners[i] for i in tri)
            if dot(cross(sub(b, a), sub(c, a)), normal) < 0:
                tri = (tri[0], tri[2], tri[1])
            self.indices.extend(base + i for i in tri)
        return self

    def rect(self, axis, value, lo, hi, normal_sign):
        """Axis-aligned rectangle on plane coord[axis] = value; lo/hi are the other two axes'
        ranges in (axis+1)%3, (axis+2)%3 order."""
        u, v = (axis + 1) % 3, (axis + 2) % 3
        corners = []
        for cu, cv in ((lo[0], lo[1]), (hi[0], lo[1]), (hi[0], hi[1]), (lo[0], hi[1])):
            c = [0.0, 0.0, 0.0]
            c[axis], c[u], c[v] = value, cu, cv
            corners.append(c)
        normal = [0.0, 0.0, 0.0]
        normal[axis] = float(normal_sign)
        uvs = None
        if self.uv_metres > 0.0:
            uvs = [[c[u] / self.uv_metres, c[v] / self.uv_metres] for c in corners]
        return self.quad(corners, normal, uvs)


def as_float32(x):
    return struct.unpack("<f", struct.pack("<f", x))[0]


class Writer:
    """Accumulates the binary buffer, buffer views and accessors. `exact_bounds`: accessor
    min/max are the float32 values stored in the buffer (what a strict validator compares)."""

    def __init__(self, exact_bounds=True):
        self.blob = bytearray()
        self.views, self.accessors = [], []
        self.exact_bounds = exact_bounds

    def _view(self, data, target):
        while len(self.blob) % 4:
            self.blob.append(0)
        self.views.append({"buffer": 0, "byteOffset": len(self.blob), "byteLength": len(data),
                           "target": target})
        self.blob.extend(data)
        return len(self.views) - 1

    def vec3(self, values, with_bounds):
        data = b"".join(struct.pack("<3f", *v) for v in values)
        acc = {"bufferView": self._view(data, 34962), "componentType": 5126,
               "count": len(values), "type": "VEC3"}
        if with_bounds:
            bound = as_float32 if self.exact_bounds else (lambda x: x)
            acc["min"] = [min(bound(v[i]) for v in values) for i in range(3)]
            acc["max"] = [max(bound(v[i]) for v in values) for i in range(3)]
        self.accessors.append(acc)
        return len(self.accessors) - 1

    def indices(self, values):
        data = struct.pack("<%dH" % len(values), *values)
        self.accessors.append({"bufferView": self._view(data, 34963), "componentType": 5123,
                               "count": len(values), "type": "SCALAR"})
        return len(self.accessors) - 1

    def vec2(self, values):
        data = b"".join(struct.pack("<2f", *v) for v in values)
        self.accessors.append({"bufferView": self._view(data, 34962), "componentType": 5126,
                               "count": len(values), "type": "VEC2"})
        return len(self.accessors) - 1

    def primitive(self, prim, material):
        attributes = {"POSITION": self.vec3(prim.positions, True),
                      "NORMAL": self.vec3(prim.normals, False)}
        if prim.uvs:
            attributes["TEXCOORD_0"] = self.vec2(prim.uvs)
        return {"attributes": attributes, "indices": self.indices(prim.indices), "material": material,
                "mode": 4}


def y_rotation(degrees):
    """Unit quaternion (x, y, z, w) for a rotation of `degrees` about +Y."""
    half = math.radians(degrees) / 2.0
    return [0.0, round(math.sin(half), 7), 0.0, round(math.cos(half), 7)]


def look_rotation(direction):
    """Quaternion (x, y, z, w) turning local -Z onto `direction` (no roll about it needed)."""
    n = math.sqrt(dot(direction, direction))
    d = [c / n for c in direction]
    a = [0.0, 0.0, -1.0]
    axis = cross(a, d)
    s = math.sqrt(dot(axis, axis))
    c = dot(a, d)
    angle = math.atan2(s, c)
    axis = [v / s for v in axis]
    half = angle / 2.0
    return [round(axis[0] * math.sin(half), 7), round(axis[1] * math.sin(half), 7),
            round(axis[2] * math.sin(half), 7), round(math.cos(half), 7)]
