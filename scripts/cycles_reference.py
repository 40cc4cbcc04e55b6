"""Independent reference for gibake's DDGI probes: Cycles panoramas projected to SH L2.

Run inside Blender (Debian 12: `apt-get install -y --no-install-recommends blender`, 3.4; never
in CI, which compares against the committed JSON):

  nice -n 10 blender -b --factory-startup -P scripts/cycles_reference.py -- \
      --scene tests/reference/cornell_blocks.gltf --probes tests/reference/cornell_blocks.probes.json \
      --out tests/reference/cornell_blocks.cycles.json --samples 1024 --seed 0 --width 128 --height 64

  --probes P.json   {"probes": [{"position": [x, y, z], ...}, ...]} in glTF world coordinates
                    (tests/reference/make_scenes.py writes one per scene); extra keys are copied
  --only I,J,...    render only these probe indices (e.g. for a second seed on a subset)
  --sky r,g,b       constant sky radiance in cd/m2 (default black, gibake's default)
  --bounces N       Cycles max bounces (default 16; 1 = direct light only, to compare with
                    `gibake --bounces 0`)
  --threads N       Cycles CPU threads (default 2)
  --self-check      render a test scene of coloured emissive quads in known glTF directions and
                    assert that the panorama mapping below puts each where it belongs, then exit

Camera mode (a picture reference instead of probes):

  nice -n 10 blender -b --factory-startup -P scripts/cycles_reference.py -- \
      --views tests/reference/views.json --view lattice_court \
      --out tests/reference/lattice_court.view.cycles.json --samples 2048 --bounces 1024

  --views V.json    {"views": [{"name", "scene" (relative to V.json), "eye", "target" (glTF world,
                    up +Y), "fov" (vertical, degrees), "width", "height", "sky" [r, g, b],
                    optional "suns" [{"direction" [x, y, z] (glTF, the way the light travels),
                    "lux"}]: what `gibake --sun x,y,z:lux` adds to a scene without its own}]}
  --view NAME       the view to render: a pinhole camera placed as `gibake preview --camera
                    eye,target,0,1,0 --fov F --size WxH` places it. Rendered twice (seeds S and
                    S + 1, --samples each); the output holds both renders' 8x8-pixel block means
                    (linear RGB, rows from the top), so a test can tell the reference's own noise.
  --save-exr DIR    camera mode: keep the renders there as VIEW_SEED.exr (to look at)
  --bounces N       as above; for a picture reference give a bound roulette never reaches (1024):
                    the truth, not a truncation.

Comparing a gibake image with a camera-mode output (8x8 blocks of luminance, as the test does):

  blender -b --factory-startup -P scripts/cycles_reference.py -- --compare G.exr --with V.json

  where G.exr is `gibake preview SCENE --reference --camera ... --size WxH --out G.exr` of the view.

What both renderers are made to solve: every material is replaced by Diffuse BSDF (colour =
glTF baseColorFactor, times the base-colour texture where there is one, sRGB-decoded texel by
texel and then filtered bilinearly, as gibake and GPUs do, with the importer's UV mapping) + Emission (colour = emissiveFactor x KHR_materials_emissive_strength,
strength 1; Cycles' emission is two-sided, which is why the scenes are double-sided and keep
the back of their emitters looking into empty space); KHR_lights_punctual directional lights
become Sun lamps with strength = lux (W/m2 and lux differ by one constant that drops out since
both renderers are linear), angle 0 (gibake's sun is a delta light); the world is black (or
--sky). alphaMode MASK (and BLEND, which gibake traces as MASK at 0.5) becomes a hard cut:
the surface is there where texture alpha x factor alpha exceeds the cutoff, a Transparent BSDF
elsewhere (transparent bounces as many as --bounces). Cycles on the CPU, no denoising, no adaptive sampling, no clamping, filter glossy off,
light threshold 0 (no light culled), box pixel filter of width 1 (each pixel integrates
exactly its own rectangle of the panorama), up to 16 bounces of every kind.

The panorama: Blender's glTF importer maps glTF (x, y, z) to Blender (x, -z, y). The camera is
equirectangular (full sphere), near clip 1e-4 m (the default 0.1 m would cut away surfaces near a
probe), rotated (90 deg, 0, 0) so it looks along Blender +Y = glTF -Z with Blender +Z = glTF +Y
up. Cycles' equirectangular camera puts its forward direction at the image centre, up at the
top, its right (+X) to the right. So with u, v in [0, 1] from the image's left and top edges,
longitude lam = (u - 0.5) * 2 pi and latitude beta = (0.5 - v) * pi, the direction in glTF
coordinates is (cos(beta) sin(lam), sin(beta), -cos(beta) cos(lam)) -- the same convention as
gibake's --sky-hdr (+Y up, centre column looks along -Z). --self-check verifies this mapping
empirically (SELF_CHECK_RESULT).

Projection: L_lm = sum over pixels of L(omega) Y_lm(omega) sin(theta) dtheta dphi with theta the
polar angle from glTF +Y, Y_lm in gibake's basis (docs/FORMAT.md): real orthonormal, order
Y00, Y1-1 (y), Y10 (z), Y11 (x), Y2-2 (xy), Y2-1 (yz), Y20 (3z^2-1), Y21 (xz), Y22 (x^2-y^2),
in glTF world axes. A probe is "black" when every pixel is exactly 0 (e.g. inside a closed
solid, or in a closed room without light).

Output JSON: {"scene", "samples", "seed", "width", "height", "bounces", "sky", "blender",
"render_seconds", "probes": [{"index", "position", "sh": [[r, g, b] x 9], "black", ...}]}.
"""
import json
import math
import os
import sys
import tempfile
import time

import bpy  # noqa: E402  (Blender's Python)
import mathutils  # noqa: E402


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    import argparse
    p = argparse.ArgumentParser(prog="cycles_reference.py")
    p.add_argument("--scene")
    p.add_argument("--probes")
    p.add_argument("--out")
    p.add_argument("--samples", type=int, default=1024)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--width", type=int, default=128)
    p.add_argument("--height", type=int, default=64)
    p.add_argument("--bounces", type=int, default=16)
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--sky", default="0,0,0")
    p.add_argument("--only", default="")
    p.add_argument("--views")
    p.add_argument("--view")
    p.add_argument("--save-exr", default="")
    p.add_argument("--self-check", action="store_true")
    p.add_argument("--compare", default="")
    p.add_argument("--with", dest="with_json", default="")
    a = p.parse_args(argv)
    if a.views or a.view:
        if not (a.views and a.view and a.out):
            p.error("camera mode needs --views, --view and --out")
    elif a.compare or a.with_json:
        if not (a.compare and a.with_json):
            p.error("--compare needs --with")
    elif not a.self_check and not (a.scene and a.probes and a.out):
        p.error("--scene, --probes and --out are required (or --self-check, or --views/--view)")
    return a


# ------------------------------------------------------------------ conventions

def gltf_to_blender(p):
    return (p[0], -p[2], p[1])


def pixel_direction(u, v):
    """glTF-world direction of panorama point (u, v), both in [0, 1] from the left/top edges."""
    lam = (u - 0.5) * 2.0 * math.pi
    beta = (0.5 - v) * math.pi
    return (math.cos(beta) * math.sin(lam), math.sin(beta), -math.cos(beta) * math.cos(lam))


def sh_basis(d):
    x, y, z = d
    return (0.282095, 0.488603 * y, 0.488603 * z, 0.488603 * x, 1.092548 * x * y, 1.092548 * y * z,
            0.315392 * (3.0 * z * z - 1.0), 1.092548 * x * z, 0.546274 * (x * x - y * y))


class Projector:
    """Precomputed per-pixel direction, solid-angle weight and SH basis for a W x H panorama."""

    def __init__(self, width, height):
        self.width, self.height = width, height
        dtheta, dphi = math.pi / height, 2.0 * math.pi / width
        self.rows = []
        for j in range(height):  # j counts from the TOP row
            v = (j + 0.5) / height
            theta = v * math.pi  # polar angle from +Y
            w = math.sin(theta) * dtheta * dphi
            row = []
            for i in range(width):
                d = pixel_direction((i + 0.5) / width, v)
                row.append([w * b for b in sh_basis(d)])
            self.rows.append(row)

    def project(self, pixels):
        """pixels: Blender image pixels (RGBA floats, rows from the BOTTOM)."""
        W, H = self.width, self.height
        sh = [[0.0, 0.0, 0.0] for _ in range(9)]
        peak = 0.0
        for j in range(H):
            src_row = H - 1 - j
            base = src_row * W * 4
            row = self.rows[j]
            for i in range(W):
                k = base + 4 * i
                r, g, b = pixels[k], pixels[k + 1], pixels[k + 2]
                peak = max(peak, r, g, b)
                if r == 0.0 and g == 0.0 and b == 0.0:
                    continue
                wb = row[i]
                for c in range(9):
                    s = sh[c]
                    s[0] += wb[c] * r
                    s[1] += wb[c] * g
                    s[2] += wb[c] * b
        return sh, peak


def irradiance(sh, n):
    a = (math.pi, 2.0 * math.pi / 3.0, 2.0 * math.pi / 3.0, 2.0 * math.pi / 3.0) + (math.pi / 4.0,) * 5
    y = sh_basis(n)
    return [sum(a[c] * y[c] * sh[c][k] for c in range(9)) for k in range(3)]


# ------------------------------------------------------------------ Blender scene

def clear_scene():
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj, do_unlink=True)
    for coll in (bpy.data.meshes, bpy.data.materials, bpy.data.lights, bpy.data.cameras):
        for block in list(coll):
            coll.remove(block)


def lambert_plus_emission(nt, emission):
    """A Lambertian Diffuse BSDF (its colour left to the caller) plus an Emission of `emission`
    radiance in node tree `nt`: (the diffuse node, the summed shader's output socket)."""
    diffuse = nt.nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Roughness"].default_value = 0.0  # Lambert
    emit = nt.nodes.new("ShaderNodeEmission")
    emit.inputs["Color"].default_value = (emission[0], emission[1], emission[2], 1.0)
    emit.inputs["Strength"].default_value = 1.0
    add = nt.nodes.new("ShaderNodeAddShader")
    nt.links.new(diffuse.outputs["BSDF"], add.inputs[0])
    nt.links.new(emit.outputs["Emission"], add.inputs[1])
    return diffuse, add.outputs["Shader"]


def make_material(name, base, emission):
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nt = mat.node_tree
    for node in list(nt.nodes):
        nt.nodes.remove(node)
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    diffuse, surface = lambert_plus_emission(nt, emission)
    diffuse.inputs["Color"].default_value = (base[0], base[1], base[2], 1.0)
    nt.links.new(surface, out.inputs["Surface"])
    return mat


def gltf_materials(doc):
    """name -> (base colour, emitted radiance) from the glTF JSON itself."""
    out = {}
    for m in doc.get("materials", []):
        base = m.get("pbrMetallicRoughness", {}).get("baseColorFactor", [1.0, 1.0, 1.0, 1.0])[:3]
        ef = m.get("emissiveFactor", [0.0, 0.0, 0.0])
        strength = m.get("extensions", {}).get("KHR_materials_emissive_strength", {}).get(
            "emissiveStrength", 1.0)
        out[m.get("name", "")] = (base, [c * strength for c in ef])
    return out


def gltf_surface(doc, name):
    """(has a base-colour texture, alpha factor, alpha cutoff or None) of material `name`."""
    for m in doc.get("materials", []):
        if m.get("name", "") != name:
            continue
        pbr = m.get("pbrMetallicRoughness", {})
        alpha = pbr.get("baseColorFactor", [1.0, 1.0, 1.0, 1.0])[3]
        mode = m.get("alphaMode", "OPAQUE")
        cutoff = m.get("alphaCutoff", 0.5) if mode == "MASK" else 0.5 if mode == "BLEND" else None
        return "baseColorTexture" in pbr, alpha, cutoff
    return False, 1.0, None


def srgb_to_linear(c):
    return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4


def linear_copy(image):
    """A float copy of an 8-bit sRGB image, decoded to linear: Cycles filters a byte image in
    sRGB and decodes after, gibake (like a GPU's sRGB formats) decodes each texel first; between
    a light and a dark texel the two differ by up to a fifth. Decoding here gives Cycles the same
    filtering as gibake."""
    w, h = image.size
    src = list(image.pixels)  # the file's values, not colour-managed
    out = [srgb_to_linear(v) if k % 4 != 3 else v for k, v in enumerate(src)]
    copy = bpy.data.images.new(image.name + "_linear", w, h, alpha=True, float_buffer=True)
    copy.colorspace_settings.name = "Linear"
    copy.alpha_mode = "CHANNEL_PACKED"  # glTF colour and alpha are independent (not premultiplied)
    copy.pixels = out
    return copy


def base_colour_images(nt):
    """The image nodes upstream of the Principled BSDF's Base Color input (the importer may put a
    factor multiply between them)."""
    bsdfs = [n for n in nt.nodes if n.type == "BSDF_PRINCIPLED"]
    if len(bsdfs) != 1:
        return []
    found, seen = [], set()
    todo = [l.from_node for l in nt.links if l.to_node == bsdfs[0] and l.to_socket.name == "Base Color"]
    while todo:
        node = todo.pop()
        if node.name in seen:
            continue
        seen.add(node.name)
        if node.type == "TEX_IMAGE":
            found.append(node)
            continue
        todo += [l.from_node for l in nt.links if l.to_node == node]
    return found


def texture_material(imported, name, base, emission, alpha_factor, cutoff):
    """`imported` (the glTF importer's material, whose image node reads the base-colour texture
    through the importer's UV mapping) rebuilt as Diffuse x texture + Emission, with a hard alpha
    cut where the glTF asks for one."""
    mat = imported.copy()
    mat.name = name
    nt = mat.node_tree
    images = [n for n in nt.nodes if n.type == "TEX_IMAGE"]
    if len(images) > 1:  # normal or metallic-roughness maps too: the one feeding the base colour
        images = base_colour_images(nt)
    if len(images) != 1:
        raise SystemExit("material %s: expected one base-colour image texture, found %d" % (name, len(images)))
    tex = images[0]
    tex.interpolation = "Linear"
    tex.image = linear_copy(tex.image)
    keep = {tex.name}
    for link in nt.links:  # the nodes feeding the image (UV map, mapping)
        if link.to_node == tex:
            keep.add(link.from_node.name)
    for node in list(nt.nodes):
        if node.name not in keep:
            nt.nodes.remove(node)
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    tint = nt.nodes.new("ShaderNodeMixRGB")
    tint.blend_type = "MULTIPLY"
    tint.inputs["Fac"].default_value = 1.0
    tint.inputs["Color2"].default_value = (base[0], base[1], base[2], 1.0)
    nt.links.new(tex.outputs["Color"], tint.inputs["Color1"])
    diffuse, surface = lambert_plus_emission(nt, emission)
    nt.links.new(tint.outputs["Color"], diffuse.inputs["Color"])
    if cutoff is not None:
        scaled = nt.nodes.new("ShaderNodeMath")
        scaled.operation = "MULTIPLY"
        scaled.inputs[1].default_value = alpha_factor
        nt.links.new(tex.outputs["Alpha"], scaled.inputs[0])
        cut = nt.nodes.new("ShaderNodeMath")
        cut.operation = "GREATER_THAN"
        cut.inputs[1].default_value = cutoff - 1e-6  # gibake keeps alpha >= cutoff
        nt.links.new(scaled.outputs["Value"], cut.inputs[0])
        hole = nt.nodes.new("ShaderNodeBsdfTransparent")
        mix = nt.nodes.new("ShaderNodeMixShader")
        nt.links.new(cut.outputs["Value"], mix.inputs["Fac"])
        nt.links.new(hole.outputs["BSDF"], mix.inputs[1])
        nt.links.new(surface, mix.inputs[2])
        surface = mix.outputs["Shader"]
    nt.links.new(surface, out.inputs["Surface"])
    return mat


def strip_suffix(name):
    # Blender appends .001 etc. to repeated names
    if len(name) > 4 and name[-4] == "." and name[-3:].isdigit():
        return name[:-4]
    return name


def import_scene(path):
    with open(path, encoding="utf-8") as f:
        doc = json.load(f)
    # Blender 3.4's glTF importer needs numpy (Debian: python3-numpy) and still uses np.bool,
    # which numpy 1.24 (Debian 12) removed: give it the alias back.
    import numpy
    if "bool" not in numpy.__dict__:
        numpy.bool = bool
    bpy.ops.import_scene.gltf(filepath=os.path.abspath(path))
    mats = gltf_materials(doc)
    replaced = {}
    for obj in bpy.data.objects:
        if obj.type != "MESH":
            continue
        if not obj.material_slots:
            raise SystemExit("mesh %s has no material (the scenes give every primitive one)" % obj.name)
        for slot in obj.material_slots:
            if slot.material and slot.material.name.startswith("ref_"):
                continue  # mesh data shared by several objects, already replaced
            key = strip_suffix(slot.material.name) if slot.material else ""
            if key not in mats:
                raise SystemExit("material %r not in the glTF" % key)
            if key not in replaced:
                base, emission = mats[key]
                textured, alpha_factor, cutoff = gltf_surface(doc, key)
                if textured:
                    replaced[key] = texture_material(slot.material, "ref_" + key, base, emission, alpha_factor,
                                                     cutoff)
                else:
                    replaced[key] = make_material("ref_" + key, base, emission)
            slot.link = "DATA"
            slot.material = replaced[key]
    # Directional lights: keep the importer's orientation, set strength (lux) and colour ourselves.
    lights = doc.get("extensions", {}).get("KHR_lights_punctual", {}).get("lights", [])
    suns = []
    for obj in list(bpy.data.objects):
        if obj.type == "CAMERA":
            bpy.data.objects.remove(obj, do_unlink=True)
            continue
        if obj.type != "LIGHT":
            continue
        match = [l for l in lights if l.get("name") and strip_suffix(obj.data.name) == l["name"]]
        if len(match) != 1 and len(lights) == 1:
            match = lights
        if len(match) != 1 or match[0].get("type") != "directional" or obj.data.type != "SUN":
            raise SystemExit("light %s: only directional lights are supported (see the docstring)" % obj.name)
        l = match[0]
        obj.data.energy = float(l.get("intensity", 1.0))
        obj.data.color = tuple(l.get("color", [1.0, 1.0, 1.0]))
        obj.data.angle = 0.0
        m = obj.matrix_world
        d_blender = (-m[0][2], -m[1][2], -m[2][2])  # a sun shines along its local -Z
        n = math.sqrt(sum(c * c for c in d_blender))
        d = (d_blender[0] / n, d_blender[2] / n, -d_blender[1] / n)  # back to glTF axes
        suns.append({"name": obj.name, "lux": obj.data.energy, "direction_gltf": [round(c, 6) for c in d]})
    return doc, suns


def setup_render(args, sky):
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    cy = scene.cycles
    cy.device = "CPU"
    cy.samples = args.samples
    cy.seed = args.seed
    cy.use_denoising = False
    if hasattr(cy, "use_adaptive_sampling"):
        cy.use_adaptive_sampling = False
    cy.max_bounces = args.bounces
    cy.diffuse_bounces = args.bounces
    cy.glossy_bounces = args.bounces
    cy.transmission_bounces = args.bounces
    cy.volume_bounces = 0
    cy.transparent_max_bounces = args.bounces
    cy.caustics_reflective = False
    cy.caustics_refractive = False
    cy.blur_glossy = 0.0
    cy.sample_clamp_direct = 0.0
    cy.sample_clamp_indirect = 0.0
    cy.light_sampling_threshold = 0.0
    cy.pixel_filter_type = "BOX"
    cy.filter_width = 1.0
    scene.render.film_transparent = False
    scene.render.threads_mode = "FIXED"
    scene.render.threads = args.threads
    scene.render.resolution_x = args.width
    scene.render.resolution_y = args.height
    scene.render.resolution_percentage = 100
    scene.render.use_compositing = False
    scene.render.use_sequencer = False
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    img = scene.render.image_settings
    img.file_format = "OPEN_EXR"
    img.color_depth = "32"
    img.color_mode = "RGBA"
    img.exr_codec = "ZIP"
    # world: constant radiance (black by default)
    world = bpy.data.worlds.new("ref_world")
    world.use_nodes = True
    bg = world.node_tree.nodes.get("Background")
    bg.inputs["Color"].default_value = (sky[0], sky[1], sky[2], 1.0)
    bg.inputs["Strength"].default_value = 1.0
    scene.world = world
    # camera
    cam_data = bpy.data.cameras.new("ref_pano")
    cam_data.type = "PANO"
    if hasattr(cam_data, "panorama_type"):  # Blender >= 4
        cam_data.panorama_type = "EQUIRECTANGULAR"
    else:
        cam_data.cycles.panorama_type = "EQUIRECTANGULAR"
    cam_data.clip_start = 1e-4
    cam_data.clip_end = 1e4
    cam = bpy.data.objects.new("ref_pano", cam_data)
    scene.collection.objects.link(cam)
    cam.rotation_mode = "XYZ"
    cam.rotation_euler = (math.pi / 2.0, 0.0, 0.0)
    scene.camera = cam
    return cam


def render_pixels(cam, position, tmpdir, tag):
    scene = bpy.context.scene
    cam.location = gltf_to_blender(position)
    path = os.path.join(tmpdir, "pano_%s.exr" % tag)
    scene.render.filepath = path
    bpy.ops.render.render(write_still=True)
    img = bpy.data.images.load(path)
    if img.size[0] != scene.render.resolution_x or img.size[1] != scene.render.resolution_y:
        raise SystemExit("unexpected image size %s" % list(img.size))
    pixels = list(img.pixels)
    bpy.data.images.remove(img)
    os.remove(path)
    return pixels


# ------------------------------------------------------------------ camera views

def block_means(pixels, width, height, block=8):
    """8x8-pixel block means of linear RGB, rows of blocks from the TOP (as gibake's images)."""
    bw, bh = width // block, height // block
    out = []
    for by in range(bh):
        for bx in range(bw):
            acc = [0.0, 0.0, 0.0]
            for j in range(by * block, (by + 1) * block):
                src_row = height - 1 - j  # Blender's rows run from the bottom
                for i in range(bx * block, (bx + 1) * block):
                    k = (src_row * width + i) * 4
                    for c in range(3):
                        acc[c] += pixels[k + c]
            out.append([float("%.6g" % (a / (block * block))) for a in acc])
    return out


def add_view_suns(specs):
    """Sun lamps a view adds, as `gibake --sun dx,dy,dz:lux` adds them: `direction` (glTF axes) is
    the way the light travels, `lux` the illuminance it gives a surface facing it; angle 0."""
    added = []
    for i, spec in enumerate(specs):
        d = spec["direction"]
        n = math.sqrt(sum(c * c for c in d))
        d = [c / n for c in d]
        light = bpy.data.lights.new("view_sun_%d" % i, type="SUN")
        light.energy = float(spec["lux"])
        light.color = tuple(spec.get("color", [1.0, 1.0, 1.0]))
        light.angle = 0.0
        obj = bpy.data.objects.new("view_sun_%d" % i, light)
        bpy.context.scene.collection.objects.link(obj)
        obj.rotation_mode = "QUATERNION"
        obj.rotation_quaternion = mathutils.Vector(gltf_to_blender(d)).to_track_quat("-Z", "Y")
        added.append({"name": obj.name, "lux": light.energy, "direction_gltf": [round(c, 6) for c in d]})
    return added


def render_view(args):
    with open(args.views, encoding="utf-8") as f:
        views = {v["name"]: v for v in json.load(f)["views"]}
    if args.view not in views:
        raise SystemExit("no view %r in %s" % (args.view, args.views))
    view = views[args.view]
    scene_path = os.path.join(os.path.dirname(os.path.abspath(args.views)), view["scene"])
    clear_scene()
    _, suns = import_scene(scene_path)
    suns += add_view_suns(view.get("suns", []))
    args.width, args.height = view["width"], view["height"]
    cam = setup_render(args, view.get("sky", [0.0, 0.0, 0.0]))
    cy = bpy.context.scene.cycles
    cy.transparent_max_bounces = max(args.bounces, 64)
    # A pinhole at the eye looking at the target, +Y (Blender +Z) up, the vertical field of view.
    cam.data.type = "PERSP"
    cam.data.sensor_fit = "VERTICAL"
    cam.data.angle = math.radians(view["fov"])
    cam.data.clip_start = 1e-3
    eye, target = view["eye"], view["target"]
    cam.location = gltf_to_blender(eye)
    forward = mathutils.Vector(gltf_to_blender([target[i] - eye[i] for i in range(3)]))
    cam.rotation_mode = "QUATERNION"
    cam.rotation_quaternion = forward.to_track_quat("-Z", "Y")
    out = {"view": view, "samples": args.samples, "seeds": [args.seed, args.seed + 1], "bounces": args.bounces,
           "blender": bpy.app.version_string, "suns": suns, "block": 8, "blocks_x": args.width // 8,
           "blocks_y": args.height // 8, "render_seconds": 0.0, "renders": []}
    t0 = time.time()
    scene = bpy.context.scene
    with tempfile.TemporaryDirectory() as tmp:
        for seed in out["seeds"]:
            cy.seed = seed
            path = os.path.join(tmp, "view_%d.exr" % seed)
            scene.render.filepath = path
            bpy.ops.render.render(write_still=True)
            img = bpy.data.images.load(path)
            pixels = list(img.pixels)
            bpy.data.images.remove(img)
            out["renders"].append(block_means(pixels, args.width, args.height))
            if args.save_exr:
                os.makedirs(args.save_exr, exist_ok=True)
                import shutil
                shutil.copy(path, os.path.join(args.save_exr, "%s_%d.exr" % (args.view, seed)))
            print("cycles_reference: view %s seed %d: %.1f s" % (args.view, seed, time.time() - t0), flush=True)
    out["render_seconds"] = round(time.time() - t0, 1)
    with open(args.out + ".partial", "w", encoding="utf-8") as f:
        json.dump(out, f, indent=1)
    os.replace(args.out + ".partial", args.out)
    print("cycles_reference: wrote %s (%.0f s)" % (args.out, out["render_seconds"]))


# ------------------------------------------------------------------ self-check

def self_check(args):
    """Coloured emissive quads in known glTF directions; the brightest pixel of each colour must
    map back to that direction."""
    clear_scene()
    tests = [((1, 0, 0), (1, 0, 0)), ((0, 1, 0), (0, 1, 0)), ((0, 0, -1), (0, 0, 1)),
             ((-1, 0, 0), (1, 1, 0)), ((0, 0, 1), (0, 1, 1)), ((0.6, -0.48, 0.64), (1, 0, 1))]
    for k, (d, colour) in enumerate(tests):
        n = math.sqrt(sum(c * c for c in d))
        d = [c / n for c in d]
        centre = [3.0 * c for c in d]
        bpy.ops.mesh.primitive_plane_add(size=0.3, location=gltf_to_blender(centre))
        obj = bpy.context.active_object
        obj.rotation_mode = "QUATERNION"
        obj.rotation_quaternion = mathutils.Vector(gltf_to_blender(d)).to_track_quat("Z", "Y")
        obj.data.materials.append(make_material("check%d" % k, (0, 0, 0), [10.0 * c for c in colour]))
    args.samples, args.bounces = 16, 1
    cam = setup_render(args, (0.0, 0.0, 0.0))
    with tempfile.TemporaryDirectory() as tmp:
        pixels = render_pixels(cam, (0.0, 0.0, 0.0), tmp, "check")
    W, H = args.width, args.height
    worst = 0.0
    for d, colour in tests:
        n = math.sqrt(sum(c * c for c in d))
        d = [c / n for c in d]
        acc = [0.0, 0.0, 0.0]  # solid-angle weighted centroid of the quad's pixels
        for j in range(H):
            for i in range(W):
                k = ((H - 1 - j) * W + i) * 4
                rgb = pixels[k:k + 3]
                if min(rgb[c] for c in range(3) if colour[c]) <= 0.0 or any(
                        rgb[c] > 0.0 for c in range(3) if not colour[c]):
                    continue
                v = (j + 0.5) / H
                w = math.sin(v * math.pi) * sum(rgb)
                pd = pixel_direction((i + 0.5) / W, v)
                acc = [acc[c] + w * pd[c] for c in range(3)]
        norm = math.sqrt(sum(c * c for c in acc)) or 1.0
        best_dir = [c / norm for c in acc]
        angle = math.degrees(math.acos(max(-1.0, min(1.0, sum(a * b for a, b in zip(d, best_dir))))))
        print("self-check: quad towards glTF %s seen at %s, %.2f deg off" %
              ([round(c, 3) for c in d], [round(c, 3) for c in best_dir], angle))
        worst = max(worst, angle)
    limit = 0.5 * 180.0 / H  # half a pixel row
    print("self-check: worst %.2f deg (limit %.2f)" % (worst, limit))
    if worst > limit:
        raise SystemExit("self-check FAILED: the panorama mapping is wrong")
    print("self-check: OK")


def luminance(c):
    return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]


def agreement(test, truth, floor_fraction=0.001):
    """Blocks whose truth is above floor_fraction x the mean: share within 10%, median and mean ratio."""
    mean = sum(truth) / len(truth)
    ratios = sorted(t / r for t, r in zip(test, truth) if r > floor_fraction * mean)
    if not ratios:
        return 0, 0.0, 0.0, 0.0
    within = sum(1 for q in ratios if abs(q - 1.0) <= 0.10) / len(ratios)
    return len(ratios), within, ratios[len(ratios) // 2], sum(test) / sum(truth)


def compare_view(args):
    """A gibake image (`preview --reference --out G.exr` of the view) against a camera-mode output:
    8x8 blocks of luminance, against the mean of the two Cycles renders, and the renders against
    each other (their own noise)."""
    with open(args.with_json, encoding="utf-8") as f:
        cyc = json.load(f)
    img = bpy.data.images.load(os.path.abspath(args.compare))
    width, height = img.size
    if width // 8 != cyc["blocks_x"] or height // 8 != cyc["blocks_y"]:
        raise SystemExit("%s is %dx%d, the Cycles blocks are %dx%d" % (args.compare, width, height, cyc["blocks_x"],
                                                                     cyc["blocks_y"]))
    ours = [luminance(b) for b in block_means(list(img.pixels), width, height)]
    a = [luminance(b) for b in cyc["renders"][0]]
    b = [luminance(b) for b in cyc["renders"][1]]
    truth = [0.5 * (x + y) for x, y in zip(a, b)]
    n, within, median, mean = agreement(ours, truth)
    n2, within2, median2, _ = agreement(a, b)
    print("compare %s: %d blocks; gibake vs Cycles (%d spp x 2): %.1f%% within 10%%, median %.3f, mean %.3f; "
          "Cycles seed against seed: %.1f%% within 10%%, median %.3f" %
          (cyc["view"]["name"], n, cyc["samples"], 100 * within, median, mean, 100 * within2, median2))


# ------------------------------------------------------------------ main

def main():
    args = parse_args()
    if args.self_check:
        self_check(args)
        return
    if args.compare:
        compare_view(args)
        return
    if args.views:
        render_view(args)
        return
    sky = [float(c) for c in args.sky.split(",")]
    with open(args.probes, encoding="utf-8") as f:
        probe_doc = json.load(f)
    probes = probe_doc["probes"]
    only = {int(s) for s in args.only.split(",") if s.strip()}
    clear_scene()
    _, suns = import_scene(args.scene)
    for s in suns:
        print("cycles_reference: sun %s, %g lux, direction (glTF) %s" % (s["name"], s["lux"], s["direction_gltf"]))
    cam = setup_render(args, sky)
    proj = Projector(args.width, args.height)
    out = {"scene": os.path.basename(args.scene), "samples": args.samples, "seed": args.seed,
           "width": args.width, "height": args.height, "bounces": args.bounces, "sky": sky,
           "blender": bpy.app.version_string, "suns": suns, "render_seconds": 0.0, "probes": []}
    t_all = time.time()
    with tempfile.TemporaryDirectory() as tmp:
        for i, probe in enumerate(probes):
            index = probe.get("index", i)
            if only and index not in only:
                continue
            t0 = time.time()
            pixels = render_pixels(cam, probe["position"], tmp, str(index))
            sh, peak = proj.project(pixels)
            entry = dict(probe)
            entry.update({"index": index, "position": probe["position"],
                          "sh": [[float("%.7g" % c) for c in rgb] for rgb in sh], "black": peak <= 0.0})
            out["probes"].append(entry)
            e_up = irradiance(sh, (0.0, 1.0, 0.0))
            print("cycles_reference: probe %d at %s: %.1f s, E(+Y) %s%s" %
                  (index, probe["position"], time.time() - t0, [round(c, 4) for c in e_up],
                   " BLACK" if entry["black"] else ""), flush=True)
            out["render_seconds"] = round(time.time() - t_all, 1)
            tmp_out = args.out + ".partial"
            with open(tmp_out, "w", encoding="utf-8") as f:
                json.dump(out, f, indent=1)
    os.replace(args.out + ".partial", args.out)
    print("cycles_reference: wrote %s (%d probes, %.0f s)" % (args.out, len(out["probes"]), out["render_seconds"]))


main()
