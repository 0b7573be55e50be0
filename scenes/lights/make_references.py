"""Mitsuba 3.9.1 references of the scenes beside this script (lights
without area: point-box, spot-box, sun-room, point-glossy, and the glTF
cornell-point, converted by scripts/gltf_to_mitsuba.py and rendered at
64 x 64): NAME.exr (64 x 64, the final pass-averaged image) and NAME.json
(the image mean per channel and its relative standard error over 16
passes).

    python3 scenes/lights/make_references.py [SPP]   # default 4096
"""
import os
import sys

import mitsuba as mi

mi.set_variant("llvm_ad_rgb")
HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "scripts"))
from mitsuba_passes import load_gltf, render_passes, write_reference  # noqa: E402

SCENES = ["point-box", "spot-box", "sun-room", "point-glossy", "cornell-point"]


def load(name):
    """The scene NAME.xml, or NAME.gltf converted for Mitsuba at 64 x 64."""
    xml = os.path.join(HERE, name + ".xml")
    if os.path.exists(xml):
        return mi.load_file(xml)
    return load_gltf(os.path.join(HERE, name + ".gltf"))

def main():
    spp = int(sys.argv[1]) if len(sys.argv) > 1 else 4096
    passes = 16
    names = sys.argv[2:] or SCENES
    for name in names:
        scene = load(name)
        images = render_passes(scene, spp, passes)
        scene_file = name + (".xml" if name != "cornell-point" else ".gltf")
        write_reference(HERE, name, scene_file, images, spp)


if __name__ == "__main__":
    main()
