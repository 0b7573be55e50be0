#!/usr/bin/env python3
"""Converts a glTF 2.0 file (.gltf or .glb) into a Mitsuba 3 scene with the
material mapping trilux uses (docs/gltf.md), so that Mitsuba can make
reference images of it.

    python3 scripts/gltf_to_mitsuba.py scenes/textured-room.gltf OUT_FOLDER [--camera NAME]

writes OUT_FOLDER/scene.xml, one binary PLY per placed mesh primitive (in
world space, normals and texture coordinates kept) and one linear EXR per
texture use, holding offset + scale x (the image, sRGB-decoded by Mitsuba's
own Bitmap conversion), referenced with raw="true": a bilinear lookup of
those texels is exactly the mapping's affine function of a bilinear lookup
of the image.

The mapping, with B = baseColorFactor x baseColorTexture, m = metallic,
r = roughness, F0 = min(0.04 specularColorFactor, 1) specularFactor
(KHR_materials_specular), F = max(F0):
    D = (1 - m)(1 - F) B   (diffuse)     S = (1 - m) F0 + m B   (GGX conductor,
                                           alpha = max(r^2, 0.01), material none)
    Dh, Sh = the largest channel of D and S over the factors
    Sh = 0: diffuse(D);  Dh = 0: roughconductor(S);
    else blendbsdf(weight w = Sh/(Dh + Sh), diffuse(D/(1-w)), roughconductor(S/w))
    doubleSided: twosided; emission emissiveFactor x emissiveStrength, an area
    emitter (one-sided). What trilux refuses, this refuses too.
A material with a metallicRoughnessTexture (metalness blue, roughness
green, linear) is evaluated per texel from glTF's formulas instead
(Converter.textured_material): per-texel images of the blend weight, D, S
and alpha.
Cameras: perspective, yfov along y, 768 x round(768/aspectRatio) pixels.
Needs numpy and Mitsuba 3.
"""
import argparse
import json
import math
import os
import struct
import sys

import numpy as np
import mitsuba as mi

MIN_ALPHA = 0.01
COMPONENT = {5121: (np.uint8, 1), 5123: (np.uint16, 2), 5125: (np.uint32, 4), 5126: (np.float32, 4)}
WIDTH = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}
WRAP = {10497: "repeat", 33648: "mirror", 33071: "clamp"}


def read_gltf(path):
    data = open(path, "rb").read()
    blob = None
    if data[:4] == b"glTF":
        length = struct.unpack_from("<I", data, 12)[0]
        j = json.loads(data[20:20 + length])
        off = 20 + length
        if off < len(data):
            blen = struct.unpack_from("<I", data, off)[0]
            blob = data[off + 8:off + 8 + blen]
    else:
        j = json.loads(data)
    folder = os.path.dirname(path)
    buffers = []
    for b in j.get("buffers", []):
        uri = b.get("uri")
        if uri is None:
            buffers.append(blob)
        elif uri.startswith("data:"):
            import base64
            buffers.append(base64.b64decode(uri.split(",", 1)[1]))
        else:
            from urllib.parse import unquote
            buffers.append(open(os.path.join(folder, unquote(uri)), "rb").read())
    return j, buffers, folder


def view_bytes(j, buffers, index):
    v = j["bufferViews"][index]
    start = v.get("byteOffset", 0)
    return buffers[v["buffer"]][start:start + v["byteLength"]], v.get("byteStride")


def accessor(j, buffers, index):
    a = j["accessors"][index]
    if "sparse" in a or "bufferView" not in a:
        raise SystemExit(f"accessor {index}: sparse or view-less accessors are not supported")
    dtype, size = COMPONENT[a["componentType"]]
    width = WIDTH[a["type"]]
    data, stride = view_bytes(j, buffers, a["bufferView"])
    stride = stride or size * width
    count, off = a["count"], a.get("byteOffset", 0)
    out = np.empty((count, width), np.float64)
    for i in range(count):
        out[i] = np.frombuffer(data, dtype, width, off + i * stride)
    if a.get("normalized"):
        out /= {np.uint8: 255.0, np.uint16: 65535.0}[dtype]
    return out


def matrix(node):
    if "matrix" in node:
        return np.array(node["matrix"], float).reshape(4, 4).T
    t = np.array(node.get("translation", [0, 0, 0]), float)
    x, y, z, w = node.get("rotation", [0, 0, 0, 1])
    s = np.array(node.get("scale", [1, 1, 1]), float)
    r = np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])
    m = np.eye(4)
    m[:3, :3] = r * s[None, :]
    m[:3, 3] = t
    return m


def write_ply(path, p, n, uv, tris):
    cols = ["x", "y", "z"] + (["nx", "ny", "nz"] if n is not None else []) + (["u", "v"] if uv is not None else [])
    header = ["ply", "format binary_little_endian 1.0", f"element vertex {len(p)}"]
    header += [f"property float {c}" for c in cols]
    header += [f"element face {len(tris)}", "property list uchar int vertex_indices", "end_header"]
    parts = [p] + ([n] if n is not None else []) + ([uv] if uv is not None else [])
    verts = np.hstack(parts).astype("<f4")
    with open(path, "wb") as f:
        f.write(("\n".join(header) + "\n").encode())
        f.write(verts.tobytes())
        faces = np.zeros(len(tris), dtype=[("n", "u1"), ("i", "<i4", 3)])
        faces["n"] = 3
        faces["i"] = tris
        f.write(faces.tobytes())


class Converter:
    def __init__(self, path, out):
        self.j, self.buffers, self.folder = read_gltf(path)
        self.out = out
        self.textures = {}
        self.xml = []

    def image(self, index):
        """The image as linear float RGB (H × W × 3), decoded by Mitsuba."""
        img = self.j["images"][index]
        if "bufferView" in img:
            data, _ = view_bytes(self.j, self.buffers, img["bufferView"])
            ext = ".jpg" if img.get("mimeType") == "image/jpeg" else ".png"
            tmp = os.path.join(self.out, f"image{index}{ext}")
            open(tmp, "wb").write(bytes(data))
        else:
            from urllib.parse import unquote
            tmp = os.path.join(self.folder, unquote(img["uri"]))
        bmp = mi.Bitmap(tmp).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, srgb_gamma=False)
        return np.array(bmp, np.float64)

    def to_uv_xml(self, info):
        """KHR_texture_transform as Mitsuba's to_uv: T R S, with the rotation
        implementations agree on, (u, v) -> (c u + s v, -s u + c v)
        (KhronosGroup/glTF issue 1563); docs/gltf.md."""
        tt = info.get("extensions", {}).get("KHR_texture_transform")
        if tt is None:
            return ""
        if tt.get("texCoord", 0) != 0:
            raise SystemExit("KHR_texture_transform's texCoord other than 0 is refused")
        ox, oy = tt.get("offset", [0.0, 0.0])
        sx, sy = tt.get("scale", [1.0, 1.0])
        r = tt.get("rotation", 0.0)
        c, s = math.cos(r), math.sin(r)
        m = [c * sx, s * sy, 0, ox, -s * sx, c * sy, 0, oy, 0, 0, 1, 0, 0, 0, 0, 1]
        return '<transform name="to_uv"><matrix value="' + " ".join(f"{v:.9g}" for v in m) + '"/></transform>'

    def texture_xml(self, info, name, scale, offset):
        if info.get("texCoord", 0) != 0:
            raise SystemExit("texCoord other than 0 is refused")
        tex = self.j["textures"][info["index"]]
        sampler = self.j.get("samplers", [{}])[tex["sampler"]] if "sampler" in tex else {}
        ws, wt = sampler.get("wrapS", 10497), sampler.get("wrapT", 10497)
        if ws != wt:
            raise SystemExit("different wrapS and wrapT are refused")
        key = (tex["source"], tuple(scale), tuple(offset))
        if key not in self.textures:
            texels = offset[None, None, :] + scale[None, None, :] * self.image(tex["source"])
            texels = np.clip(texels, 0.0, 1.0)
            fname = f"texture{len(self.textures)}.exr"
            mi.Bitmap(np.ascontiguousarray(texels, np.float32)).write(os.path.join(self.out, fname))
            self.textures[key] = fname
        filt = "nearest" if sampler.get("magFilter") == 9728 else "bilinear"
        return (f'<texture type="bitmap" name="{name}"><string name="filename" value="{self.textures[key]}"/>'
                f'<boolean name="raw" value="true"/><string name="filter_type" value="{filt}"/>'
                f'<string name="wrap_mode" value="{WRAP[ws]}"/>{self.to_uv_xml(info)}</texture>')

    def material(self, index):
        m = self.j["materials"][index] if index is not None else {}
        for key in ("normalTexture", "emissiveTexture"):
            if key in m:
                raise SystemExit(f"material {index}: {key} is refused")
        if m.get("alphaMode", "OPAQUE") != "OPAQUE":
            raise SystemExit(f"material {index}: alphaMode is refused")
        pbr = m.get("pbrMetallicRoughness", {})
        if "metallicRoughnessTexture" in pbr:
            return self.textured_material(index, m)
        b = np.clip(np.array(pbr.get("baseColorFactor", [1, 1, 1, 1])[:3], float), 0, 1)
        metal = min(max(pbr.get("metallicFactor", 1.0), 0.0), 1.0)
        rough = min(max(pbr.get("roughnessFactor", 1.0), 0.0), 1.0)
        ext = m.get("extensions", {})
        spec = ext.get("KHR_materials_specular", {})
        sf = min(max(spec.get("specularFactor", 1.0), 0.0), 1.0)
        sc = np.array(spec.get("specularColorFactor", [1, 1, 1]), float)
        f0 = np.clip(0.04 * sc, 0, 1) * sf
        fmax = f0.max()
        d_scale = (1 - metal) * (1 - fmax) * b
        s_scale, s_offset = metal * b, (1 - metal) * f0
        d_hat = (1 - metal) * (1 - fmax) * b.max()
        s_hat = (s_offset + s_scale).max()
        tex = pbr.get("baseColorTexture")
        alpha = max(rough * rough, MIN_ALPHA)

        def rgb(name, v):
            return f'<rgb name="{name}" value="{v[0]:.9g}, {v[1]:.9g}, {v[2]:.9g}"/>'

        def diffuse(scale):
            if tex is not None and scale.max() > 0:
                return '<bsdf type="diffuse">' + self.texture_xml(tex, "reflectance", scale, np.zeros(3)) + "</bsdf>"
            return '<bsdf type="diffuse">' + rgb("reflectance", np.minimum(scale, 1)) + "</bsdf>"

        def conductor(scale, offset):
            head = (f'<bsdf type="roughconductor"><string name="distribution" value="ggx"/>'
                    f'<float name="alpha" value="{alpha:.9g}"/><string name="material" value="none"/>')
            if tex is not None and scale.max() > 0:
                return head + self.texture_xml(tex, "specular_reflectance", scale, offset) + "</bsdf>"
            return head + rgb("specular_reflectance", np.minimum(scale + offset, 1)) + "</bsdf>"

        if s_hat <= 0:
            bsdf = diffuse(d_scale)
        elif d_hat <= 0:
            bsdf = conductor(s_scale, s_offset)
        else:
            w = s_hat / (d_hat + s_hat)
            bsdf = (f'<bsdf type="blendbsdf"><float name="weight" value="{w:.12g}"/>'
                    + diffuse(d_scale / (1 - w)) + conductor(s_scale / w, s_offset / w) + "</bsdf>")
        if m.get("doubleSided"):
            bsdf = '<bsdf type="twosided">' + bsdf + "</bsdf>"
        return bsdf, self.emitter(index, m)

    def emitter(self, index, m):
        """The area emitter of material `m` (emissiveFactor x
        KHR_materials_emissive_strength, one-sided), or ""."""
        ext = m.get("extensions", {})
        strength = ext.get("KHR_materials_emissive_strength", {}).get("emissiveStrength", 1.0)
        e = np.array(m.get("emissiveFactor", [0, 0, 0]), float) * strength
        if e.max() > 0 and m.get("doubleSided"):
            raise SystemExit(f"material {index}: a double-sided emissive material is refused")
        if e.max() <= 0:
            return ""
        return f'<emitter type="area"><rgb name="radiance" value="{e[0]:.9g}, {e[1]:.9g}, {e[2]:.9g}"/></emitter>'

    def raw_image(self, index):
        """The image as float RGB (H x W x 3) of its stored values / 255
        (no sRGB decoding: glTF's metallicRoughnessTexture is linear)."""
        img = self.j["images"][index]
        if "bufferView" in img:
            data, _ = view_bytes(self.j, self.buffers, img["bufferView"])
            tmp = os.path.join(self.out, f"raw{index}.png")
            open(tmp, "wb").write(bytes(data))
        else:
            from urllib.parse import unquote
            tmp = os.path.join(self.folder, unquote(img["uri"]))
        bmp = mi.Bitmap(tmp)
        bmp.set_srgb_gamma(False)
        return np.array(bmp.convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, srgb_gamma=False), np.float64)

    def bitmap_xml(self, name, texels, info):
        """A bitmap texture `name` of the linear `texels` (H x W x 3, or
        H x W for a float parameter), with `info`'s sampler and transform."""
        tex = self.j["textures"][info["index"]]
        sampler = self.j.get("samplers", [{}])[tex["sampler"]] if "sampler" in tex else {}
        fname = f"texture{len(self.textures)}.exr"
        self.textures[("per-texel", fname)] = fname
        arr = np.ascontiguousarray(texels if texels.ndim == 3 else texels[..., None], np.float32)
        mi.Bitmap(arr).write(os.path.join(self.out, fname))
        filt = "nearest" if sampler.get("magFilter") == 9728 else "bilinear"
        return (f'<texture type="bitmap" name="{name}"><string name="filename" value="{fname}"/>'
                f'<boolean name="raw" value="true"/><string name="filter_type" value="{filt}"/>'
                f'<string name="wrap_mode" value="{WRAP[sampler.get("wrapS", 10497)]}"/>'
                f'{self.to_uv_xml(info)}</texture>')

    def textured_material(self, index, m):
        """A material with a metallicRoughnessTexture: glTF's formulas
        evaluated per texel (B = baseColorFactor x sRGB-decoded base colour
        texel, m = metallicFactor x blue, r = roughnessFactor x green,
        D = (1 - m)(1 - F) B, S = (1 - m) F0 + m B, alpha = max(r^2, 0.01)),
        written as blendbsdf(w, diffuse(D / (1 - w)), roughconductor(S / w,
        alpha)) with a per-texel weight w = max S / (max D + max S) (any w
        gives the same BRDF; this one keeps both inner values within
        [0, 1]). Both textures must share size, sampler and transform, as
        the images are their per-texel products: exact with NEAREST; with
        bilinear filtering the product of two lookups differs from the
        lookup of the products between texel centres (a warning)."""
        pbr = m["pbrMetallicRoughness"]
        for key in ("normalTexture", "emissiveTexture"):
            if key in m:
                raise SystemExit(f"material {index}: {key} with a metallicRoughnessTexture is refused")
        if m.get("alphaMode", "OPAQUE") != "OPAQUE":
            raise SystemExit(f"material {index}: alphaMode is refused")
        mr_info, base_info = pbr["metallicRoughnessTexture"], pbr.get("baseColorTexture")
        for info in (mr_info, base_info):
            if info is not None and info.get("texCoord", 0) != 0:
                raise SystemExit("texCoord other than 0 is refused")
        mr = self.raw_image(self.j["textures"][mr_info["index"]]["source"])
        if base_info is not None:
            same = lambda k: (self.j["textures"][mr_info["index"]].get(k)  # noqa: E731
                              == self.j["textures"][base_info["index"]].get(k))
            t = self.image(self.j["textures"][base_info["index"]]["source"])
            if (t.shape != mr.shape or not same("sampler")
                    or mr_info.get("extensions") != base_info.get("extensions")):
                raise SystemExit(f"material {index}: the base colour and metallicRoughness textures "
                                 "must share size, sampler and KHR_texture_transform")
        else:
            t = np.ones_like(mr)
        sampler_index = self.j["textures"][mr_info["index"]].get("sampler")
        sampler = self.j.get("samplers", [{}])[sampler_index] if sampler_index is not None else {}
        if sampler.get("magFilter") != 9728:
            print(f"warning: material {index}: bilinear lookups of per-texel products differ from "
                  "glTF's products of lookups between texel centres", file=sys.stderr)
        b = np.clip(np.array(pbr.get("baseColorFactor", [1, 1, 1, 1])[:3], float), 0, 1) * t
        metal = np.clip(pbr.get("metallicFactor", 1.0), 0, 1) * mr[..., 2:3]
        rough = np.clip(pbr.get("roughnessFactor", 1.0), 0, 1) * mr[..., 1]
        spec = m.get("extensions", {}).get("KHR_materials_specular", {})
        sf = min(max(spec.get("specularFactor", 1.0), 0.0), 1.0)
        f0 = np.clip(0.04 * np.array(spec.get("specularColorFactor", [1, 1, 1]), float), 0, 1) * sf
        d = (1 - metal) * (1 - f0.max()) * b
        s = (1 - metal) * f0 + metal * b
        dh, sh = d.max(axis=-1), s.max(axis=-1)
        w = np.where(dh + sh > 0, sh / np.maximum(dh + sh, 1e-300), 0.5)
        safe = lambda v: np.maximum(v, 1e-300)[..., None]  # noqa: E731
        inner_d = np.where(w[..., None] < 1, d / safe(1 - w), 0)
        inner_s = np.where(w[..., None] > 0, s / safe(w), 0)
        alpha = np.maximum(rough * rough, MIN_ALPHA)
        info = mr_info
        bsdf = ('<bsdf type="blendbsdf">' + self.bitmap_xml("weight", w, info)
                + '<bsdf type="diffuse">' + self.bitmap_xml("reflectance", inner_d, info) + "</bsdf>"
                + '<bsdf type="roughconductor"><string name="distribution" value="ggx"/>'
                + '<string name="material" value="none"/>' + self.bitmap_xml("alpha", alpha, info)
                + self.bitmap_xml("specular_reflectance", inner_s, info) + "</bsdf></bsdf>")
        if m.get("doubleSided"):
            bsdf = '<bsdf type="twosided">' + bsdf + "</bsdf>"
        return bsdf, self.emitter(index, m)

    def light(self, i, node, world):
        """A KHR_lights_punctual light as Mitsuba's emitter, in trilux's
        units (docs/gltf.md: candela as W/sr, lux as W/m^2, times color);
        it shines along the node's -z. A spot is refused: glTF's falloff
        (quadratic in the cosine) has no Mitsuba equivalent."""
        light = self.j["extensions"]["KHR_lights_punctual"]["lights"][
            node["extensions"]["KHR_lights_punctual"]["light"]]
        c = np.array(light.get("color", [1.0, 1.0, 1.0])) * light.get("intensity", 1.0)
        rgb = ", ".join(f"{v:.12g}" for v in c)
        kind = light["type"]
        if kind == "point":
            p = ", ".join(f"{v:.12g}" for v in world[:3, 3])
            return (f'<emitter type="point"><point name="position" value="{p}"/>'
                    f'<rgb name="intensity" value="{rgb}"/></emitter>')
        if kind == "directional":
            d = world[:3, :3] @ np.array([0.0, 0.0, -1.0])
            d = ", ".join(f"{v:.12g}" for v in d / np.linalg.norm(d))
            return (f'<emitter type="directional"><vector name="direction" value="{d}"/>'
                    f'<rgb name="irradiance" value="{rgb}"/></emitter>')
        raise SystemExit(f"node {i}: a {kind} light has no Mitsuba equivalent (glTF's spot falloff)")

    def convert(self, camera_name=None):
        j = self.j
        required = set(j.get("extensionsRequired", [])) - {"KHR_materials_specular", "KHR_materials_emissive_strength"}
        if required:
            raise SystemExit(f"required extensions refused: {sorted(required)}")
        scene = j["scenes"][j.get("scene", 0)]
        cameras = []
        shapes = []
        stack = [(i, np.eye(4)) for i in scene["nodes"]]
        order = []
        while stack:
            i, parent = stack.pop(0)
            node = j["nodes"][i]
            world = parent @ matrix(node)
            order.append((i, node, world))
            stack[:0] = [(c, world) for c in node.get("children", [])]
        for i, node, world in order:
            if "KHR_lights_punctual" in node.get("extensions", {}):
                shapes.append(self.light(i, node, world))
            if "camera" in node:
                cam = j["cameras"][node["camera"]]
                names = {cam.get("name"), node.get("name")}
                cameras.append((names, cam, world))
            if "mesh" in node:
                for k, prim in enumerate(j["meshes"][node["mesh"]]["primitives"]):
                    if prim.get("mode", 4) != 4:
                        raise SystemExit("only TRIANGLES primitives")
                    attrs = prim["attributes"]
                    p = accessor(j, self.buffers, attrs["POSITION"])
                    n = accessor(j, self.buffers, attrs["NORMAL"]) if "NORMAL" in attrs else None
                    uv = accessor(j, self.buffers, attrs["TEXCOORD_0"]) if "TEXCOORD_0" in attrs else None
                    idx = (accessor(j, self.buffers, prim["indices"]).astype(np.int64).reshape(-1, 3)
                           if "indices" in prim else np.arange(len(p)).reshape(-1, 3))
                    pw = (world[:3, :3] @ p.T).T + world[:3, 3]
                    if n is not None:
                        nm = np.linalg.inv(world[:3, :3]).T
                        n = (nm @ n.T).T
                        n /= np.linalg.norm(n, axis=1, keepdims=True)
                    fname = f"mesh{len(shapes)}.ply"
                    write_ply(os.path.join(self.out, fname), pw, n, uv, idx)
                    bsdf, emitter = self.material(prim.get("material"))
                    flat = '<boolean name="face_normals" value="true"/>' if n is None else ""
                    shapes.append(f'<shape type="ply"><string name="filename" value="{fname}"/>{flat}{bsdf}{emitter}</shape>')
        if camera_name is not None:
            cameras = [c for c in cameras if camera_name in c[0]]
        if not cameras:
            raise SystemExit("no camera")
        _, cam, world = cameras[0]
        persp = cam["perspective"]
        aspect = persp.get("aspectRatio")
        width = 768
        height = round(width / aspect) if aspect else 576
        axes = world[:3, :3] / np.linalg.norm(world[:3, :3], axis=0, keepdims=True)
        to_world = np.eye(4)
        to_world[:3, 0], to_world[:3, 1], to_world[:3, 2] = -axes[:, 0], axes[:, 1], -axes[:, 2]
        to_world[:3, 3] = world[:3, 3]
        mat = " ".join(f"{v:.12g}" for v in to_world.reshape(-1))
        clip = f'<float name="near_clip" value="{persp["znear"]:.12g}"/>'
        if "zfar" in persp:
            clip += f'<float name="far_clip" value="{persp["zfar"]:.12g}"/>'
        else:
            clip += '<float name="far_clip" value="1e30"/>'  # glTF: infinite
        sensor = (f'<sensor type="perspective"><float name="fov" value="{math.degrees(persp["yfov"]):.12g}"/>'
                  f'{clip}<string name="fov_axis" value="y"/><transform name="to_world"><matrix value="{mat}"/></transform>'
                  f'<film type="hdrfilm"><integer name="width" value="{width}"/><integer name="height" value="{height}"/>'
                  f'<rfilter type="gaussian"/></film></sensor>')
        xml = ('<?xml version="1.0" encoding="utf-8"?>\n<scene version="3.0.0">\n'
               '<integrator type="path"><integer name="max_depth" value="-1"/></integrator>\n'
               + sensor + "\n" + "\n".join(shapes) + "\n</scene>\n")
        path = os.path.join(self.out, "scene.xml")
        with open(path, "w") as f:
            f.write(xml)
        return path


def convert(path, out, camera=None):
    """Converts `path` into folder `out`; returns the path of scene.xml."""
    os.makedirs(out, exist_ok=True)
    if mi.variant() is None:
        mi.set_variant("scalar_rgb")
    return Converter(path, out).convert(camera)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("gltf")
    ap.add_argument("out")
    ap.add_argument("--camera")
    args = ap.parse_args()
    print(convert(args.gltf, args.out, args.camera))


if __name__ == "__main__":
    sys.exit(main())
