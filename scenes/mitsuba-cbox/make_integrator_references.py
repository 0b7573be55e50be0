#!/usr/bin/env python3
"""Mitsuba 3.9.1 image means of cbox-rgb.xml under the integrator settings
trilux must honour: `max_depth` 1, 2 and 3 (emitters seen directly, direct
light, one bounce), and `hide_emitters` at the file's own `max_depth` 6.

Usage (from anywhere):
    python3 scenes/mitsuba-cbox/make_integrator_references.py [--spp N] [--passes K]

Each case renders the file unedited except for the path integrator's
parameters (`max_depth` through the file's own `$max_depth`,
`hide_emitters` by rendering with an equal path integrator that sets it),
N samples per pixel in K passes with seeds 0..K-1; the passes' means give
the relative standard error of each mean (spread / sqrt(K) / mean).

Writes integrator.json beside this script: per case the per-channel image
mean and its relative standard error. Only means are kept (the test
compares image means; the images themselves add nothing to check them).
"""
import argparse
import os
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from image_means import mean_over_passes, rounded, write  # noqa: E402

CASES = [
    ("max_depth_1", 1, False),
    ("max_depth_2", 2, False),
    ("max_depth_3", 3, False),
    ("hide_emitters_max_depth_6", 6, True),
]


def case_mean(mi, max_depth, hide, spp, passes):
    scene = mi.load_file(os.path.join(HERE, "cbox-rgb.xml"), max_depth=max_depth)
    integrator = mi.load_dict(
        {"type": "path", "max_depth": max_depth, "hide_emitters": hide}
    )
    return mean_over_passes(mi, scene, spp, passes, integrator)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--spp", type=int, default=512)
    ap.add_argument("--passes", type=int, default=8)
    a = ap.parse_args()
    import mitsuba as mi

    try:
        mi.set_variant("llvm_ad_rgb")
    except Exception as e:  # noqa: BLE001 - fall back, and say so
        print(f"llvm_ad_rgb unavailable ({e}); using scalar_rgb")
        mi.set_variant("scalar_rgb")
    t0 = time.time()
    rec = {
        "scene": "scenes/mitsuba-cbox/cbox-rgb.xml",
        "mitsuba": mi.__version__,
        "variant": mi.variant(),
        "spp": a.spp,
        "passes": a.passes,
        "cases": {},
    }
    for name, depth, hide in CASES:
        mean, stderr = case_mean(mi, depth, hide, a.spp, a.passes)
        rec["cases"][name] = {"max_depth": depth, "hide_emitters": hide, **rounded(mean, stderr)}
    rec["seconds"] = round(time.time() - t0, 1)
    rec["command"] = "python3 scenes/mitsuba-cbox/make_integrator_references.py " + " ".join(
        sys.argv[1:]
    )
    write(os.path.join(HERE, "integrator.json"), rec)


if __name__ == "__main__":
    main()
