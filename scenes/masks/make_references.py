"""Mitsuba 3.9.1 reference of the cut-out scene beside this script
(leaf-box.xml: a `mask` with a bitmap opacity, leaves.png, between a
ceiling light and the floor of a closed box): leaf-box.exr (64 x 64, the
final pass-averaged image) and leaf-box.json (the image mean per channel
and its relative standard error over 16 passes). It also writes
leaves.png (32 x 32, grey, sRGB-encoded 8-bit): discs of opacity 1 on 0
in its left half, a ramp of encoded values 0..255 across its right half.

    python3 scenes/masks/make_references.py [SPP]   # default 4096
"""
import os
import sys

import numpy as np
import mitsuba as mi

mi.set_variant("llvm_ad_rgb")
HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "scripts"))
from mitsuba_passes import render_passes, write_reference  # noqa: E402


def leaves():
    """The opacity image: discs on the left half, a ramp on the right."""
    n = 32
    img = np.zeros((n, n), dtype=np.uint8)
    for y in range(n):
        for x in range(n // 2):
            # Discs of radius 3 on a 8-texel grid.
            cx, cy = 8 * (x // 8) + 4, 8 * (y // 8) + 4
            if (x + 0.5 - cx) ** 2 + (y + 0.5 - cy) ** 2 <= 9.0:
                img[y, x] = 255
        for x in range(n // 2, n):
            img[y, x] = int(round(255 * (x - n // 2) / (n // 2 - 1)))
    mi.Bitmap(img[..., None], mi.Bitmap.PixelFormat.Y).write(
        os.path.join(HERE, "leaves.png")
    )


def main():
    spp = int(sys.argv[1]) if len(sys.argv) > 1 else 4096
    passes = 16
    leaves()
    name = "leaf-box"
    scene = mi.load_file(os.path.join(HERE, name + ".xml"))
    images = render_passes(scene, spp, passes)
    write_reference(HERE, name, name + ".xml", images, spp)


if __name__ == "__main__":
    main()
