"""Mitsuba 3.9.1 references of the scenes beside this script (smooth and
named conductors: metal-box): NAME.exr (64 x 64, the pass-averaged
image) and NAME.json (the image mean per channel and its relative standard
error over 16 passes).

    python3 scenes/conductors/make_references.py [SPP]   # default 4096
"""
import os
import sys

import mitsuba as mi

mi.set_variant("llvm_ad_rgb")
HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "scripts"))
from mitsuba_passes import render_passes, write_reference  # noqa: E402

SCENES = ["metal-box"]


def main():
    spp = int(sys.argv[1]) if len(sys.argv) > 1 else 4096
    passes = 16
    names = sys.argv[2:] or SCENES
    for name in names:
        scene = mi.load_file(os.path.join(HERE, name + ".xml"))
        images = render_passes(scene, spp, passes)
        write_reference(HERE, name, name + ".xml", images, spp)


if __name__ == "__main__":
    main()
