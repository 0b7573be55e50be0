"""Mitsuba 3.9.1 references of the normal- and bump-mapped boxes beside
this script, and the maps they read (written first, deterministically):

- normalmap.png (64 x 64 RGB, raw): the tangent-space normal
  normalize(0.5 sin(2 pi x), -0.35, 1) at texel x in [0, 1) across: ripples
  along u and a tilt towards -v (which side is tested: a mirrored
  frame would tilt the floor the other way);
- height.png (64 x 64 grey, raw): h = 0.1 + 0.6 x + 0.15 sin(4 pi x)
  cos(4 pi y), with x across and y down the image: a slope (so that the
  sign of the gradient is tested and the image mean sees it) with bumps;
- tilt.png (4 x 4 RGB, every texel (191, 160, 230)/255): the constant
  normal of the closed-form test in crates/trilux/tests/normal_maps.rs.

NAME.exr (64 x 64, the pass-averaged image) and NAME.json (the image mean
per channel and its relative standard error over 16 passes; also the mean
with Mitsuba's default use_shadowing_function = true, which trilux does not
apply).

    python3 scenes/normalmap/make_references.py [SPP]   # default 4096
"""
import os
import re
import sys
import tempfile

import numpy as np
import mitsuba as mi

mi.set_variant("llvm_ad_rgb")
HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "scripts"))
from mitsuba_passes import render_passes, write_reference  # noqa: E402

SCENES = ["normalmap-box", "bumpmap-box"]
N = 64


def write_maps():
    x = (np.arange(N) + 0.5) / N
    xx, yy = np.meshgrid(x, x)  # xx across (u), yy down (v)
    n = np.stack([0.5 * np.sin(2 * np.pi * xx), np.full_like(xx, -0.35), np.ones_like(xx)], -1)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    rgb = np.round((n * 0.5 + 0.5) * 255).astype(np.uint8)
    mi.Bitmap(rgb, pixel_format=mi.Bitmap.PixelFormat.RGB).write(os.path.join(HERE, "normalmap.png"))
    h = 0.1 + 0.6 * xx + 0.15 * np.sin(4 * np.pi * xx) * np.cos(4 * np.pi * yy)
    grey = np.round(np.clip(h, 0, 1) * 255).astype(np.uint8)[..., None]
    mi.Bitmap(grey, pixel_format=mi.Bitmap.PixelFormat.Y).write(os.path.join(HERE, "height.png"))
    # The closed-form test's constant map (crates/trilux/tests/normal_maps.rs).
    tilt = np.tile(np.array([191, 160, 230], dtype=np.uint8), (4, 4, 1))
    mi.Bitmap(tilt, pixel_format=mi.Bitmap.PixelFormat.RGB).write(os.path.join(HERE, "tilt.png"))


def render(path, spp, passes, shadowing):
    text = open(path, encoding="utf-8").read()
    if shadowing:
        text = text.replace('name="use_shadowing_function" value="false"', 'name="use_shadowing_function" value="true"')
    tmp = os.path.join(HERE, ".tmp-" + os.path.basename(path))
    with open(tmp, "w", encoding="utf-8") as f:
        f.write(text)
    try:
        scene = mi.load_file(tmp)
    finally:
        os.remove(tmp)
    return render_passes(scene, spp, passes)


def main():
    spp = int(sys.argv[1]) if len(sys.argv) > 1 else 4096
    passes = 16
    write_maps()
    for name in sys.argv[2:] or SCENES:
        path = os.path.join(HERE, name + ".xml")
        images = render(path, spp, passes, False)
        shadowed = render(path, spp // 4, passes, True).reshape(passes, -1, 3).mean(axis=(0, 1))
        extra = {
            "mean_rgb_use_shadowing_function": [round(float(x), 7) for x in shadowed],
            "spp_use_shadowing_function": spp // 4,
        }
        write_reference(HERE, name, name + ".xml", images, spp, extra)


if __name__ == "__main__":
    main()
