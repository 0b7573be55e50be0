#!/usr/bin/env python3
"""Mitsuba 3.9.1's image of tests/sample-border/scene.xml with and without
`sample_border`, reduced to what the test compares: the mean of each of
the film's 16 columns (all rows, the three channels averaged).

Usage (from anywhere):
    python3 tests/sample-border/make_reference.py [--spp N]

Writes reference.json beside this script.
"""
import argparse
import json
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))


def column_means(mi, border, spp):
    scene = mi.load_file(os.path.join(HERE, "scene.xml"), border=border)
    img = np.array(mi.render(scene, spp=spp, seed=0), dtype=np.float64)
    return [round(float(x), 7) for x in img.mean(axis=(0, 2))]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--spp", type=int, default=16384)
    a = ap.parse_args()
    import mitsuba as mi

    mi.set_variant("scalar_rgb")
    rec = {
        "scene": "tests/sample-border/scene.xml",
        "mitsuba": mi.__version__,
        "variant": mi.variant(),
        "spp": a.spp,
        "column_means": {
            "sample_border": column_means(mi, "true", a.spp),
            "no_sample_border": column_means(mi, "false", a.spp),
        },
        "command": "python3 tests/sample-border/make_reference.py " + " ".join(sys.argv[1:]),
    }
    with open(os.path.join(HERE, "reference.json"), "w", encoding="utf-8") as f:
        json.dump(rec, f, indent=2)
        f.write("\n")
    print(json.dumps(rec))


if __name__ == "__main__":
    main()
