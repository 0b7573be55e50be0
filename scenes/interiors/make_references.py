#!/usr/bin/env python3
"""Renders Mitsuba 3 references of the converted interiors:
scenes/interiors/<name>/reference.exr.

Usage:
    python3 scenes/interiors/make_references.py [NAME ...] [--spp N] [--passes K]
        [--variant V]

Each NAME's scene.xml (default: every folder beside this script that has
one) is rendered with Mitsuba 3.9.1 (pip install mitsuba==3.9.1) exactly as
the file says: its `path` integrator and max_depth (-1 where trilux's solve,
which has no depth limit, needs it), its camera and film (at most 256 pixels
on the longer side). The N samples per pixel are taken in K passes of N/K
with seeds 0..K-1; the passes' image means give the relative standard error
of the reference's mean (their spread / sqrt(K) / mean), printed with the
render time (the passes only, after loading: Mitsuba's speed on this file).
The EXR is RGB, half float (small; far below the noise).

Variant: llvm_ad_rgb by default (needs libLLVM, e.g. `apt-get install -y
libllvm19`), else scalar_rgb. The results are appended, one JSON line per
scene, to references.jsonl beside this script.
"""
import argparse
import json
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("names", nargs="*")
    ap.add_argument("--spp", type=int, default=1024)
    ap.add_argument("--passes", type=int, default=16)
    ap.add_argument("--variant", default="llvm_ad_rgb")
    a = ap.parse_args()
    import mitsuba as mi

    try:
        mi.set_variant(a.variant)
    except Exception as e:  # noqa: BLE001 - fall back, and say so
        print(f"variant {a.variant} unavailable ({e}); using scalar_rgb")
        mi.set_variant("scalar_rgb")
    names = a.names or sorted(d for d in os.listdir(HERE) if os.path.isfile(os.path.join(HERE, d, "scene.xml")))
    per = max(1, a.spp // a.passes)
    for name in names:
        path = os.path.join(HERE, name, "scene.xml")
        t0 = time.time()
        scene = mi.load_file(path)
        t_load = time.time() - t0
        acc = None
        means = []
        t0 = time.time()
        for k in range(a.passes):
            img = np.array(mi.render(scene, spp=per, seed=k), dtype=np.float64)
            acc = img if acc is None else acc + img
            means.append(img.mean())
        t_render = time.time() - t0
        ref = acc / a.passes
        mean = float(ref.mean())
        rel = float(np.std(means, ddof=1) / np.sqrt(a.passes) / mean)
        bmp = mi.Bitmap(ref.astype(np.float32), pixel_format=mi.Bitmap.PixelFormat.RGB)
        bmp = bmp.convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float16, False)
        bmp.write(os.path.join(HERE, name, "reference.exr"))
        rec = {
            "scene": name,
            "variant": mi.variant(),
            "mitsuba": mi.__version__,
            "size": [int(ref.shape[1]), int(ref.shape[0])],
            "spp": per * a.passes,
            "passes": a.passes,
            "load_s": round(t_load, 2),
            "render_s": round(t_render, 1),
            "mean_rgb": [round(float(x), 6) for x in ref.reshape(-1, 3).mean(axis=0)],
            "mean": round(mean, 6),
            "mean_rel_stderr": round(rel, 5),
            "threads": os.cpu_count(),
        }
        print(json.dumps(rec), flush=True)
        with open(os.path.join(HERE, "references.jsonl"), "a") as f:
            f.write(json.dumps(rec) + "\n")


if __name__ == "__main__":
    sys.exit(main())
