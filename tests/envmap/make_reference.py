#!/usr/bin/env python3
"""Mitsuba 3.9.1's image means of the scenes lit by an environment map
(`envmap`) in tests/envmap/, for crates/trilux/tests/envmap.rs:
courtyard.xml with the sky seen, hidden, turned about +y and tilted about
+x (its `to_world`), and daylight-room.xml (the sun blob in through the
window); and a probe of the map lookup itself (`envmap.eval` on an 8 x 4
image for a few directions), which trilux-solver's sky.rs tests repeat.

Usage (from anywhere; sky.exr from make_envmap.py):
    python3 tests/envmap/make_reference.py [--spp N] [--passes P]

Writes reference.json beside this script.
"""
import argparse
import os
import sys
import tempfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "scenes", "mitsuba-cbox"))
import image_means  # noqa: E402

CASES = (
    ("courtyard_seen", "courtyard.xml", {"hide": "false"}),
    ("courtyard_hidden", "courtyard.xml", {"hide": "true"}),
    ("courtyard_turned", "courtyard.xml", {"hide": "true", "angle": "150"}),
    ("courtyard_tilted", "courtyard.xml", {"hide": "true", "ax": "1", "ay": "0", "angle": "40"}),
    ("daylight_room", "daylight-room.xml", {}),
)


def probe(mi):
    """envmap.eval for an 8 x 4 image whose texel (i, j) is (i + 1, j + 1,
    0), at directions given by their (u, v) in Mitsuba's convention."""
    img = np.zeros((4, 8, 3), dtype=np.float32)
    for j in range(4):
        for i in range(8):
            img[j, i] = [i + 1, j + 1, 0]
    path = os.path.join(tempfile.mkdtemp(), "probe.exr")
    mi.Bitmap(img).write(path)
    e = mi.load_dict({"type": "envmap", "filename": path})
    out = []
    for u, v in ((0.01, 0.5), (0.999, 0.5), (0.0625, 0.125), (0.3125, 0.385)):
        phi, theta = 2 * np.pi * u, np.pi * v
        d = [np.sin(phi) * np.sin(theta), np.cos(theta), -np.cos(phi) * np.sin(theta)]
        si = mi.SurfaceInteraction3f()
        si.wi = mi.Vector3f(-d[0], -d[1], -d[2])
        out.append({"u": u, "v": v, "rgb": [round(float(x), 6) for x in e.eval(si)]})
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--spp", type=int, default=4096)
    ap.add_argument("--passes", type=int, default=8)
    a = ap.parse_args()
    import mitsuba as mi

    mi.set_variant("scalar_rgb")
    cases = {}
    for name, file, params in CASES:
        scene = mi.load_file(os.path.join(HERE, file), **params)
        mean, stderr = image_means.mean_over_passes(mi, scene, a.spp, a.passes)
        cases[name] = image_means.rounded(mean, stderr)
        cases[name]["defines"] = params
    image_means.write(
        os.path.join(HERE, "reference.json"),
        {
            "scenes": "tests/envmap/{courtyard,daylight-room}.xml",
            "mitsuba": mi.__version__,
            "variant": mi.variant(),
            "spp": a.spp,
            "passes": a.passes,
            "cases": cases,
            "probe": probe(mi),
            "command": "python3 tests/envmap/make_reference.py " + " ".join(sys.argv[1:]),
        },
    )


if __name__ == "__main__":
    main()
