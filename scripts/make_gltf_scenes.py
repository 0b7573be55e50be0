#!/usr/bin/env python3
"""Writes trilux's bundled glTF scenes and textured scenes into scenes/.

  scenes/textured-room.gltf (+ .bin)   a closed room: checker-textured floor (PNG),
                                       striped back wall (JPEG, glossy dielectric
                                       blend), white walls, a metal box, a ceiling
                                       panel that emits
  scenes/product-shot.glb              one binary file with embedded PNG images: a
                                       striped sphere (half metallic) on a checker
                                       floor in a closed studio, placed through a
                                       hierarchy of TRS nodes
  scenes/cornell-box-gltf.gltf (+ .bin)
                                       scenes/cornell-box.xml as glTF: the same
                                       triangles, its reflectances and radiance as
                                       Mitsuba's RGB mode converts its spectra
                                       (scalar_rgb), pure Lambertian materials
                                       (KHR_materials_specular, specularFactor 0)
  scenes/textured-box.xml              the Mitsuba XML subset with <texture
                                       type="bitmap"> as a diffuse reflectance, a
                                       blendbsdf weight and a roughconductor's
                                       specular_reflectance
  scenes/textures/*.png, *.jpg         the images (made here, with numpy)

Run from the repository root: python3 scripts/make_gltf_scenes.py
Needs numpy and Mitsuba 3 (for writing PNG/JPEG and converting the Cornell
box's spectra).
"""
import json
import math
import os
import struct

import numpy as np
import mitsuba as mi

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENES = os.path.join(ROOT, "scenes")
TEXTURES = os.path.join(SCENES, "textures")


# ---------------------------------------------------------------- images

def write_image(path, rgb8):
    """An 8-bit sRGB image (H × W × 3 uint8) as PNG or JPEG (by extension)."""
    bmp = mi.Bitmap(np.ascontiguousarray(rgb8, dtype=np.uint8),
                    pixel_format=mi.Bitmap.PixelFormat.RGB)
    if path.endswith(".jpg"):
        bmp.write(path, quality=95)
    else:
        bmp.write(path)


def checker(n=64, cells=8, a=(200, 190, 170), b=(60, 70, 90)):
    y, x = np.mgrid[0:n, 0:n]
    on = ((x * cells // n) + (y * cells // n)) % 2 == 0
    img = np.where(on[..., None], np.array(a), np.array(b))
    return img.astype(np.uint8)


def stripes(w=96, h=32, colours=((180, 40, 30), (230, 200, 120), (40, 90, 160))):
    x = np.arange(w)
    band = (x * len(colours) * 2 // w) % len(colours)
    img = np.array(colours)[band][None, :, :].repeat(h, axis=0)
    return img.astype(np.uint8)


def grey_ramp(n=32):
    """A horizontal ramp 0..255 (a blend weight; raw in the XML scene)."""
    v = np.linspace(0, 255, n).round().astype(np.uint8)
    return np.repeat(np.repeat(v[None, :, None], n, axis=0), 3, axis=2)


# ---------------------------------------------------------------- glTF

class Gltf:
    """A minimal glTF 2.0 writer: one buffer, meshes, materials, nodes."""

    def __init__(self):
        self.j = {"asset": {"version": "2.0", "generator": "trilux scripts/make_gltf_scenes.py"},
                  "scene": 0, "scenes": [{"nodes": []}], "nodes": [], "meshes": [],
                  "materials": [], "accessors": [], "bufferViews": [], "buffers": []}
        self.bin = bytearray()
        self.used = set()

    def _view(self, data, target=None):
        while len(self.bin) % 4:
            self.bin.append(0)
        view = {"buffer": 0, "byteOffset": len(self.bin), "byteLength": len(data)}
        if target:
            view["target"] = target
        self.bin.extend(data)
        self.j["bufferViews"].append(view)
        return len(self.j["bufferViews"]) - 1

    def _accessor(self, array, kind, component, target):
        array = np.ascontiguousarray(array)
        view = self._view(array.tobytes(), target)
        acc = {"bufferView": view, "componentType": component, "count": int(array.shape[0]),
               "type": kind}
        if kind == "VEC3" and component == 5126:
            acc["min"] = [float(v) for v in array.min(axis=0)]
            acc["max"] = [float(v) for v in array.max(axis=0)]
        self.j["accessors"].append(acc)
        return len(self.j["accessors"]) - 1

    def mesh(self, name, positions, indices, material, normals=None, uvs=None):
        attrs = {"POSITION": self._accessor(np.asarray(positions, np.float32), "VEC3", 5126, 34962)}
        if normals is not None:
            attrs["NORMAL"] = self._accessor(np.asarray(normals, np.float32), "VEC3", 5126, 34962)
        if uvs is not None:
            attrs["TEXCOORD_0"] = self._accessor(np.asarray(uvs, np.float32), "VEC2", 5126, 34962)
        prim = {"attributes": attrs, "material": material, "mode": 4}
        if indices is not None:
            prim["indices"] = self._accessor(np.asarray(indices, np.uint32).reshape(-1), "SCALAR",
                                             5125, 34963)
        self.j["meshes"].append({"name": name, "primitives": [prim]})
        return len(self.j["meshes"]) - 1

    def material(self, name, base=(0.8, 0.8, 0.8), metallic=0.0, roughness=1.0, texture=None,
                 specular=None, emissive=None, strength=None, double_sided=False):
        pbr = {"baseColorFactor": list(base) + [1.0], "metallicFactor": metallic,
               "roughnessFactor": roughness}
        if texture is not None:
            pbr["baseColorTexture"] = {"index": texture}
        m = {"name": name, "pbrMetallicRoughness": pbr, "doubleSided": double_sided}
        ext = {}
        if specular is not None:
            ext["KHR_materials_specular"] = {"specularFactor": specular}
            self.used.add("KHR_materials_specular")
        if emissive is not None:
            m["emissiveFactor"] = list(emissive)
        if strength is not None:
            ext["KHR_materials_emissive_strength"] = {"emissiveStrength": strength}
            self.used.add("KHR_materials_emissive_strength")
        if ext:
            m["extensions"] = ext
        self.j["materials"].append(m)
        return len(self.j["materials"]) - 1

    def texture(self, image_path=None, embed=None, mime="image/png", wrap=10497, mag=9729):
        images = self.j.setdefault("images", [])
        if embed is not None:
            images.append({"bufferView": self._view(embed), "mimeType": mime})
        else:
            images.append({"uri": image_path})
        samplers = self.j.setdefault("samplers", [])
        samplers.append({"magFilter": mag, "wrapS": wrap, "wrapT": wrap})
        textures = self.j.setdefault("textures", [])
        textures.append({"source": len(images) - 1, "sampler": len(samplers) - 1})
        return len(textures) - 1

    def node(self, name, mesh=None, children=None, root=True, camera=None, **trs):
        n = {"name": name}
        if mesh is not None:
            n["mesh"] = mesh
        if camera is not None:
            n["camera"] = camera
        if children:
            n["children"] = children
        n.update(trs)
        self.j["nodes"].append(n)
        i = len(self.j["nodes"]) - 1
        if root:
            self.j["scenes"][0]["nodes"].append(i)
        return i

    def camera(self, name, yfov, aspect, matrix):
        cams = self.j.setdefault("cameras", [])
        cams.append({"name": name, "type": "perspective",
                     "perspective": {"yfov": yfov, "aspectRatio": aspect, "znear": 0.01}})
        return self.node(name, camera=len(cams) - 1, matrix=[float(v) for v in matrix])

    def write(self, path):
        if self.used:
            self.j["extensionsUsed"] = sorted(self.used)
        for k in ("images", "samplers", "textures", "cameras"):
            if k in self.j and not self.j[k]:
                del self.j[k]
        while len(self.bin) % 4:
            self.bin.append(0)
        if path.endswith(".glb"):
            self.j["buffers"] = [{"byteLength": len(self.bin)}]
            js = json.dumps(self.j, separators=(",", ":")).encode()
            js += b" " * (-len(js) % 4)
            total = 12 + 8 + len(js) + 8 + len(self.bin)
            with open(path, "wb") as f:
                f.write(struct.pack("<III", 0x46546C67, 2, total))
                f.write(struct.pack("<II", len(js), 0x4E4F534A) + js)
                f.write(struct.pack("<II", len(self.bin), 0x004E4942) + bytes(self.bin))
        else:
            binname = os.path.basename(path)[:-5] + ".bin"
            self.j["buffers"] = [{"uri": binname, "byteLength": len(self.bin)}]
            with open(os.path.join(os.path.dirname(path), binname), "wb") as f:
                f.write(self.bin)
            with open(path, "w") as f:
                json.dump(self.j, f, indent=1)
                f.write("\n")


def look_at(origin, target, up):
    """glTF camera matrix (column-major list): looks down −z, +y up."""
    o, t, u = (np.array(v, float) for v in (origin, target, up))
    z = o - t
    z /= np.linalg.norm(z)
    x = np.cross(u, z)
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = x, y, z, o
    return m.T.reshape(-1)


def quad(c, du, dv, uv_scale=1.0):
    """A rectangle corner c + s du + t dv (s, t in [0, 1]); front = du × dv."""
    c, du, dv = (np.array(v, float) for v in (c, du, dv))
    p = [c, c + du, c + du + dv, c + dv]
    n = np.cross(du, dv)
    n /= np.linalg.norm(n)
    uv = np.array([[0, 1], [1, 1], [1, 0], [0, 0]], float) * uv_scale
    return np.array(p), np.array([n] * 4), uv, np.array([[0, 1, 2], [0, 2, 3]])


def box(lo, hi):
    """An axis-aligned box with outward normals, 24 vertices, flat faces."""
    lo, hi = np.array(lo, float), np.array(hi, float)
    d = hi - lo
    faces = [
        (lo, (0, 0, d[2]), (0, d[1], 0)),                       # −x
        ((hi[0], lo[1], lo[2]), (0, d[1], 0), (0, 0, d[2])),    # +x
        (lo, (d[0], 0, 0), (0, 0, d[2])),                       # −y
        ((lo[0], hi[1], lo[2]), (0, 0, d[2]), (d[0], 0, 0)),    # +y
        (lo, (0, d[1], 0), (d[0], 0, 0)),                       # −z
        ((lo[0], lo[1], hi[2]), (d[0], 0, 0), (0, d[1], 0)),    # +z
    ]
    return merge([quad(*f) for f in faces])


def merge(parts):
    p, n, uv, t = [], [], [], []
    base = 0
    for (pp, nn, uu, tt) in parts:
        p.append(pp)
        n.append(nn)
        uv.append(uu)
        t.append(tt + base)
        base += len(pp)
    return np.vstack(p), np.vstack(n), np.vstack(uv), np.vstack(t)


def uv_sphere(r=1.0, rings=24, segments=48):
    p, n, uv, t = [], [], [], []
    for i in range(rings + 1):
        th = math.pi * i / rings
        for j in range(segments + 1):
            ph = 2 * math.pi * j / segments
            d = (math.sin(th) * math.cos(ph), math.cos(th), -math.sin(th) * math.sin(ph))
            p.append([r * c for c in d])
            n.append(d)
            uv.append((j / segments, i / rings))
    for i in range(rings):
        for j in range(segments):
            a = i * (segments + 1) + j
            b = a + segments + 1
            if i > 0:
                t.append((a, b, a + 1))
            if i < rings - 1:
                t.append((a + 1, b, b + 1))
    return np.array(p), np.array(n), np.array(uv), np.array(t)


def add(g, name, geo, material, root=True, **trs):
    p, n, uv, t = geo
    m = g.mesh(name, p, t, material, normals=n, uvs=uv)
    return g.node(name, mesh=m, root=root, **trs)


# ---------------------------------------------------------------- scenes

def textured_room():
    g = Gltf()
    floor_tex = g.texture("textures/checker.png")
    wall_tex = g.texture("textures/stripes.jpg", wrap=33648)  # MIRRORED_REPEAT
    white = g.material("white", (0.75, 0.75, 0.75), specular=0.0)
    floor = g.material("floor", (0.9, 0.9, 0.9), texture=floor_tex, specular=0.0)
    back = g.material("back wall", (1.0, 1.0, 1.0), roughness=0.6, texture=wall_tex)
    gold = g.material("metal box", (0.9, 0.7, 0.35), metallic=1.0, roughness=0.45)
    lamp = g.material("lamp", (0.5, 0.5, 0.5), specular=0.0, emissive=(1.0, 0.95, 0.85), strength=6.0)
    W, H, D = 4.0, 3.0, 4.0
    add(g, "floor", quad((-W / 2, 0, D / 2), (W, 0, 0), (0, 0, -D), uv_scale=3.0), floor)
    add(g, "ceiling", quad((-W / 2, H, -D / 2), (W, 0, 0), (0, 0, D)), white)
    add(g, "back", quad((-W / 2, 0, -D / 2), (W, 0, 0), (0, H, 0), uv_scale=1.5), back)
    add(g, "front", quad((W / 2, 0, D / 2), (-W, 0, 0), (0, H, 0)), white)
    add(g, "left", quad((-W / 2, 0, D / 2), (0, 0, -D), (0, H, 0)), white)
    add(g, "right", quad((W / 2, 0, -D / 2), (0, 0, D), (0, H, 0)), white)
    add(g, "lamp", quad((-0.6, H - 0.01, -0.6), (1.2, 0, 0), (0, 0, 1.2)), lamp)
    add(g, "box", box((-0.45, 0, -0.45), (0.45, 0.9, 0.45)), gold,
        translation=[0.6, 0.0, -0.5], rotation=[0.0, math.sin(0.3), 0.0, math.cos(0.3)])
    g.camera("view", math.radians(55.0), 1.0, look_at((0, 1.5, 1.9), (0, 1.1, -2.0), (0, 1, 0)))
    g.write(os.path.join(SCENES, "textured-room.gltf"))


def product_shot():
    g = Gltf()
    with open(os.path.join(TEXTURES, "checker.png"), "rb") as f:
        floor_tex = g.texture(embed=f.read())
    with open(os.path.join(TEXTURES, "stripes.png"), "rb") as f:
        ball_tex = g.texture(embed=f.read())
    backdrop = g.material("backdrop", (0.6, 0.6, 0.65), specular=0.0, double_sided=True)
    floor = g.material("floor", (0.8, 0.8, 0.8), texture=floor_tex, roughness=0.7)
    ball = g.material("product", (1.0, 1.0, 1.0), metallic=0.5, roughness=0.35, texture=ball_tex)
    panel = g.material("softbox", (0.0, 0.0, 0.0), specular=0.0, emissive=(1.0, 1.0, 1.0), strength=10.0)
    # Both cameras (z = 3.5, y = 4.5) lie inside the studio.
    S, H = 4.5, 5.0
    add(g, "floor", quad((-S, 0, S), (2 * S, 0, 0), (0, 0, -2 * S), uv_scale=6.0), floor)
    add(g, "studio", box((-S, -0.01, -S), (S, H, S)), backdrop)
    add(g, "softbox", quad((-1.0, H - 0.05, -1.0), (2.0, 0, 0), (0, 0, 2.0)), panel)
    child = add(g, "ball", uv_sphere(), ball, root=False, scale=[0.8, 0.8, 0.8])
    g.node("product", children=[child], translation=[0.0, 0.8, 0.0],
           rotation=[0.0, math.sin(0.4), 0.0, math.cos(0.4)])
    g.camera("front", math.radians(45.0), 1.0, look_at((0, 1.6, 3.5), (0, 0.7, 0), (0, 1, 0)))
    g.camera("top", math.radians(50.0), 1.0, look_at((0.1, 4.5, 0.5), (0, 0.5, 0), (0, 1, 0)))
    g.write(os.path.join(SCENES, "product-shot.glb"))


def cornell_box_gltf():
    """scenes/cornell-box.xml as glTF, through Mitsuba's own RGB conversion."""
    mi.set_variant("scalar_rgb")
    scene = mi.load_file(os.path.join(SCENES, "cornell-box.xml"), res=128, spp=4)
    params = mi.traverse(scene)
    g = Gltf()
    for k, shape in enumerate(scene.shapes()):
        # Mitsuba merges the meshes that share a BSDF into one, without an id.
        name = shape.id() or f"white-{k}"
        bsdf = mi.traverse(shape.bsdf())
        rho = [float(v) for v in bsdf["reflectance.value"]]
        emitter = shape.emitter()
        if emitter is not None:
            le = [float(v) for v in mi.traverse(emitter)["radiance.value"]]
            k = max(le)
            mat = g.material(name, rho, specular=0.0, emissive=[v / k for v in le], strength=k)
        else:
            mat = g.material(name, rho, specular=0.0)
        if shape.is_mesh():
            p = np.array(shape.vertex_positions_buffer(), float).reshape(-1, 3)
            t = np.array(shape.faces_buffer(), np.uint32).reshape(-1, 3)
            m = g.mesh(name, p, t, mat)
        else:
            xf = np.array(params[f"{name}.to_world"].matrix, float).reshape(4, 4)
            corners = np.array([[-1, -1, 0, 1], [1, -1, 0, 1], [1, 1, 0, 1], [-1, 1, 0, 1]], float)
            p = (xf @ corners.T).T[:, :3]
            m = g.mesh(name, p, [[0, 1, 2], [0, 2, 3]], mat)
        g.node(name, mesh=m)
    sensor = scene.sensors()[0]
    to_world = np.array(sensor.world_transform().matrix, float).reshape(4, 4)
    w, h = sensor.film().size()
    key = next(k for k in params.keys() if k.endswith(".x_fov"))
    x_fov = math.radians(float(np.array(params[key]).reshape(-1)[0]))
    aspect = w / h
    yfov = 2 * math.atan(math.tan(x_fov / 2) / aspect)
    gl = to_world @ np.diag([-1.0, 1.0, -1.0, 1.0])
    g.camera("sensor", yfov, aspect, gl.T.reshape(-1))
    g.write(os.path.join(SCENES, "cornell-box-gltf.gltf"))


TEXTURED_BOX = """<?xml version="1.0" encoding="utf-8"?>
<!-- A textured box in the Mitsuba XML subset, written by
     scripts/make_gltf_scenes.py: a checker floor (diffuse reflectance), a
     back wall whose blendbsdf weight is a raw grey ramp (diffuse to a rough
     conductor), a rough-conductor panel whose specular_reflectance is the
     striped JPEG, white walls and a ceiling light. -->
<scene version="3.0.0">
    <sensor type="perspective">
        <float name="fov" value="45"/>
        <transform name="to_world">
            <lookat origin="0, 1, 3.6" target="0, 1, 0" up="0, 1, 0"/>
        </transform>
        <film type="hdrfilm">
            <integer name="width" value="128"/>
            <integer name="height" value="128"/>
        </film>
    </sensor>
    <bsdf type="diffuse" id="white"><rgb name="reflectance" value="0.7, 0.7, 0.7"/></bsdf>
    <shape type="rectangle" id="floor">
        <transform name="to_world"><rotate x="1" angle="-90"/><translate y="0"/></transform>
        <bsdf type="diffuse">
            <texture type="bitmap" name="reflectance">
                <string name="filename" value="textures/checker.png"/>
                <string name="wrap_mode" value="repeat"/>
            </texture>
        </bsdf>
    </shape>
    <shape type="rectangle" id="ceiling">
        <transform name="to_world"><rotate x="1" angle="90"/><translate y="2"/></transform>
        <ref id="white"/>
    </shape>
    <shape type="rectangle" id="back">
        <transform name="to_world"><translate y="1" z="-1"/></transform>
        <bsdf type="blendbsdf">
            <texture type="bitmap" name="weight">
                <string name="filename" value="textures/ramp.png"/>
                <boolean name="raw" value="true"/>
                <string name="wrap_mode" value="clamp"/>
            </texture>
            <bsdf type="diffuse"><rgb name="reflectance" value="0.6, 0.5, 0.4"/></bsdf>
            <bsdf type="roughconductor">
                <string name="distribution" value="ggx"/>
                <float name="alpha" value="0.3"/>
                <rgb name="specular_reflectance" value="0.8, 0.8, 0.9"/>
            </bsdf>
        </bsdf>
    </shape>
    <shape type="rectangle" id="left">
        <transform name="to_world"><rotate y="1" angle="90"/><translate x="-1" y="1"/></transform>
        <ref id="white"/>
    </shape>
    <shape type="rectangle" id="right">
        <transform name="to_world"><rotate y="1" angle="-90"/><translate x="1" y="1"/></transform>
        <ref id="white"/>
    </shape>
    <shape type="rectangle" id="panel">
        <transform name="to_world">
            <scale x="0.35" y="0.5"/><rotate y="1" angle="30"/><translate x="0.4" y="0.55" z="-0.3"/>
        </transform>
        <bsdf type="twosided">
            <bsdf type="roughconductor">
                <string name="distribution" value="ggx"/>
                <float name="alpha" value="0.2"/>
                <texture type="bitmap" name="specular_reflectance">
                    <string name="filename" value="textures/stripes.jpg"/>
                    <string name="filter_type" value="nearest"/>
                </texture>
            </bsdf>
        </bsdf>
    </shape>
    <shape type="rectangle" id="light">
        <transform name="to_world">
            <scale value="0.3"/><rotate x="1" angle="90"/><translate y="1.99"/>
        </transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0"/></bsdf>
        <emitter type="area"><rgb name="radiance" value="12, 11, 9"/></emitter>
    </shape>
</scene>
"""


def main():
    os.makedirs(TEXTURES, exist_ok=True)
    mi.set_variant("scalar_rgb")
    write_image(os.path.join(TEXTURES, "checker.png"), checker())
    write_image(os.path.join(TEXTURES, "stripes.png"), stripes())
    write_image(os.path.join(TEXTURES, "stripes.jpg"), stripes())
    write_image(os.path.join(TEXTURES, "ramp.png"), grey_ramp())
    textured_room()
    product_shot()
    cornell_box_gltf()
    with open(os.path.join(SCENES, "textured-box.xml"), "w") as f:
        f.write(TEXTURED_BOX)
    print("wrote scenes/textured-room.gltf, product-shot.glb, cornell-box-gltf.gltf, "
          "textured-box.xml and scenes/textures/")


if __name__ == "__main__":
    main()
