"""The textured-metal glTF box beside this script and its Mitsuba 3.9.1
reference (issue 24: metallicRoughnessTexture read as glTF 2.0 defines it).

Written first, deterministically (numpy and Mitsuba's PNG writer):

- metal-rough-box.gltf / .bin: a closed box 2 x 2 x 2 (a Cornell box's
  walls: red left, green right, white ceiling, all dielectric), an
  emissive square under the ceiling, the camera at (0, 1, 3.9) looking
  along -z (aspect ratio 1);
- the floor: baseColorTexture floor-base.png (16 x 16 sRGB, a checker of
  4 x 4 texel blocks, orange (230, 180, 90) and blue (90, 140, 220)) and
  metallicRoughnessTexture floor-mr.png (16 x 16, linear: blue = metalness
  in four column blocks 0, 255, 128, 64; green = roughness rising down the
  rows, round(255 (0.15 + 0.85 y / 15)); red 255, unused), metallicFactor
  0.9, roughnessFactor 1: the product (1 - m) B of two textures;
- the back wall: no base colour texture (baseColorFactor (0.9, 0.7, 0.4)),
  metallicRoughnessTexture wall-mr.png (16 x 16: metalness 255 in rows
  0-3 and 8-11, 0 elsewhere; roughness round(255 (0.3 + 0.6 x / 15))
  across the columns), metallicFactor 1, roughnessFactor 0.8;
- every sampler NEAREST with CLAMP_TO_EDGE: the converter's per-texel
  product images (scripts/gltf_to_mitsuba.py) are then exactly glTF's
  per-lookup products.

metal-rough-box.exr (64 x 64, the pass-averaged image) and
metal-rough-box.json (the image mean per channel and its relative standard
error over 16 passes), the scene converted by scripts/gltf_to_mitsuba.py.

    python3 scenes/metal-rough/make_references.py [SPP]   # default 4096
"""
import json
import os
import struct
import sys

import numpy as np
import mitsuba as mi

mi.set_variant("llvm_ad_rgb")
HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "scripts"))
from mitsuba_passes import load_gltf, render_passes, write_reference  # noqa: E402

NAME = "metal-rough-box"
N = 16


def write_png(name, rgb):
    mi.Bitmap(np.ascontiguousarray(rgb, np.uint8), pixel_format=mi.Bitmap.PixelFormat.RGB).write(
        os.path.join(HERE, name))


def write_textures():
    y, x = np.mgrid[0:N, 0:N]
    checker = ((x // 4 + y // 4) % 2)[..., None]
    base = np.where(checker == 0, np.array([230, 180, 90]), np.array([90, 140, 220]))
    write_png("floor-base.png", base)
    metal = np.array([0, 255, 128, 64])[x // 4]
    rough = np.round(255 * (0.15 + 0.85 * y / (N - 1)))
    write_png("floor-mr.png", np.stack([np.full_like(x, 255), rough, metal], -1))
    metal = np.where((y // 4) % 2 == 0, 255, 0)
    rough = np.round(255 * (0.3 + 0.6 * x / (N - 1)))
    write_png("wall-mr.png", np.stack([np.full_like(x, 255), rough, metal], -1))


def quad(p0, p1, p2, p3, inward):
    """The square p0 p1 p2 p3 as two triangles wound counter-clockwise seen
    from the side `inward` points to (glTF's front), its normal, texture
    coordinates (0, 0) at p0, (1, 0) at p1, (1, 1) at p2, and indices."""
    p = np.array([p0, p1, p2, p3], float)
    n = np.cross(p[1] - p[0], p[2] - p[0])
    n /= np.linalg.norm(n)
    indices = [0, 1, 2, 0, 2, 3]
    if np.dot(n, inward) < 0:
        n, indices = -n, [0, 2, 1, 0, 3, 2]
    assert np.dot(n, inward) > 0.99, (n, inward)
    uv = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    return p, np.tile(n, (4, 1)), uv, indices


def write_gltf():
    meshes = [
        ("floor", quad((-1, 0, -1), (1, 0, -1), (1, 0, 1), (-1, 0, 1), (0, 1, 0)), 0),
        ("back", quad((-1, 2, -1), (1, 2, -1), (1, 0, -1), (-1, 0, -1), (0, 0, 1)), 1),
        ("left", quad((-1, 0, -1), (-1, 0, 1), (-1, 2, 1), (-1, 2, -1), (1, 0, 0)), 2),
        ("right", quad((1, 0, 1), (1, 0, -1), (1, 2, -1), (1, 2, 1), (-1, 0, 0)), 3),
        ("ceiling", quad((-1, 2, 1), (1, 2, 1), (1, 2, -1), (-1, 2, -1), (0, -1, 0)), 4),
        ("light", quad((-0.3, 1.98, 0.3), (0.3, 1.98, 0.3), (0.3, 1.98, -0.3), (-0.3, 1.98, -0.3), (0, -1, 0)), 5),
    ]
    blob = bytearray()
    views, accessors, gmeshes, nodes = [], [], [], []

    def add(array, component, kind, minmax=False):
        data = np.ascontiguousarray(array, "<f4" if component == 5126 else "<u4").tobytes()
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data)})
        blob.extend(data)
        a = {"bufferView": len(views) - 1, "componentType": component, "count": len(array), "type": kind}
        if minmax:
            a["min"] = [float(v) for v in array.min(axis=0)]
            a["max"] = [float(v) for v in array.max(axis=0)]
        accessors.append(a)
        return len(accessors) - 1

    for name, (p, n, uv, order), material in meshes:
        attrs = {"POSITION": add(p, 5126, "VEC3", True), "NORMAL": add(n, 5126, "VEC3"),
                 "TEXCOORD_0": add(uv, 5126, "VEC2")}
        indices = add(np.array(order), 5125, "SCALAR")
        gmeshes.append({"name": name, "primitives": [{"attributes": attrs, "indices": indices,
                                                       "material": material}]})
        nodes.append({"name": name, "mesh": len(gmeshes) - 1})
    nodes.append({"name": "sensor", "camera": 0, "translation": [0.0, 1.0, 3.9]})
    dielectric = lambda name, c: {"name": name, "pbrMetallicRoughness": {  # noqa: E731
        "baseColorFactor": c + [1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0}}
    materials = [
        {"name": "floor", "pbrMetallicRoughness": {
            "baseColorTexture": {"index": 0}, "metallicRoughnessTexture": {"index": 1},
            "metallicFactor": 0.9, "roughnessFactor": 1.0}},
        {"name": "back", "pbrMetallicRoughness": {
            "baseColorFactor": [0.9, 0.7, 0.4, 1.0], "metallicRoughnessTexture": {"index": 2},
            "metallicFactor": 1.0, "roughnessFactor": 0.8}},
        dielectric("red", [0.63, 0.065, 0.05]),
        dielectric("green", [0.14, 0.45, 0.09]),
        dielectric("white", [0.8, 0.8, 0.8]),
        {"name": "light", "pbrMetallicRoughness": {"baseColorFactor": [0.0, 0.0, 0.0, 1.0],
                                                   "metallicFactor": 0.0},
         "emissiveFactor": [1.0, 0.85, 0.6],
         "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 12.0}}},
    ]
    gltf = {
        "asset": {"version": "2.0", "generator": "trilux scenes/metal-rough/make_references.py"},
        "extensionsUsed": ["KHR_materials_emissive_strength"],
        "scene": 0,
        "scenes": [{"nodes": list(range(len(nodes)))}],
        "nodes": nodes,
        "meshes": gmeshes,
        "materials": materials,
        "cameras": [{"type": "perspective", "perspective": {
            "yfov": 0.6911112070083618, "aspectRatio": 1.0, "znear": 0.01}}],
        "images": [{"uri": "floor-base.png"}, {"uri": "floor-mr.png"}, {"uri": "wall-mr.png"}],
        "samplers": [{"magFilter": 9728, "minFilter": 9728, "wrapS": 33071, "wrapT": 33071}],
        "textures": [{"source": i, "sampler": 0} for i in range(3)],
        "buffers": [{"uri": NAME + ".bin", "byteLength": len(blob)}],
        "bufferViews": views,
        "accessors": accessors,
    }
    with open(os.path.join(HERE, NAME + ".bin"), "wb") as f:
        f.write(bytes(blob))
    with open(os.path.join(HERE, NAME + ".gltf"), "w", encoding="utf-8") as f:
        json.dump(gltf, f, indent=1)
        f.write("\n")


def load():
    """The scene converted for Mitsuba at 64 x 64."""
    return load_gltf(os.path.join(HERE, NAME + ".gltf"))

def main():
    spp = int(sys.argv[1]) if len(sys.argv) > 1 else 4096
    write_textures()
    write_gltf()
    images = render_passes(load(), spp, 16)
    write_reference(HERE, NAME, NAME + ".gltf", images, spp)


if __name__ == "__main__":
    main()
