#!/usr/bin/env python3
"""Mitsuba 3.9.1 references of Mitsuba's own Cornell box, as its files stand.

Usage (from anywhere):
    python3 scenes/mitsuba-cbox/make_references.py [NAME ...] [--spp N] [--passes K]

For each NAME (default: cbox and cbox-rgb) this loads NAME.xml unedited with
Mitsuba 3.9.1 and renders it with everything the file says (camera, film,
filter, emitters, BSDFs), with one exception that the file itself offers:
its `$max_depth` parameter (`<default name="max_depth" value="6"/>`) is set
to -1, as `mitsuba -D max_depth=-1` would, because trilux's solution carries
light over paths of every length (a radiosity solution has no depth limit).
The file's own limit (6: at most 5 bounces) is rendered too, to record how
much light it leaves out (`mean_rgb_file_max_depth`).

N samples per pixel in K passes of N/K with seeds 0..K-1. The passes'
image means give the relative standard error of the reference's mean
(their spread / sqrt(K) / mean), per channel.

Writes beside this script:
  NAME.exr     RGB half float (far below the noise), linear sRGB, the film's
               size (256 x 256)
  NAME.json    variant, spp, passes, per-channel means and their standard
               errors, the mean at the file's own max_depth, seconds, command

Variant: llvm_ad_spectral when the file has a <spectrum> with
wavelength:value pairs (trilux solves such a file in spectral bands),
else llvm_ad_rgb (scalar_* when LLVM is missing: the same images, slower).
"""
import argparse
import json
import os
import re
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))


def included_text(path):
    """The file's text and that of its <include>s (Mitsuba's fragments)."""
    text = open(path, encoding="utf-8").read()
    for inc in re.findall(r"<include\s+filename\s*=\s*\"([^\"]*)\"", text):
        text += included_text(os.path.join(os.path.dirname(path), inc))
    return text


def is_spectral(path):
    values = re.findall(r"<spectrum\b[^>]*\bvalue\s*=\s*\"([^\"]*)\"", included_text(path))
    return any(":" in v for v in values)


def render_passes(mi, path, max_depth, spp, passes):
    scene = mi.load_file(path, max_depth=max_depth)
    per = spp // passes
    acc, means = None, []
    for k in range(passes):
        img = np.array(mi.render(scene, spp=per, seed=k), dtype=np.float64)
        acc = img if acc is None else acc + img
        means.append(img.reshape(-1, 3).mean(axis=0))
    return acc / passes, np.array(means)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("names", nargs="*", default=["cbox", "cbox-rgb"])
    ap.add_argument("--spp", type=int, default=1024)
    ap.add_argument("--passes", type=int, default=16)
    ap.add_argument("--file-depth-spp", type=int, default=256,
                    help="samples per pixel of the render at the file's own max_depth")
    a = ap.parse_args()
    import mitsuba as mi

    for name in a.names:
        path = os.path.join(HERE, f"{name}.xml")
        kind = "spectral" if is_spectral(path) else "rgb"
        try:
            mi.set_variant(f"llvm_ad_{kind}")
        except Exception as e:  # noqa: BLE001 - fall back, and say so
            print(f"llvm_ad_{kind} unavailable ({e}); using scalar_{kind}")
            mi.set_variant(f"scalar_{kind}")
        t0 = time.time()
        ref, means = render_passes(mi, path, -1, a.spp, a.passes)
        seconds = time.time() - t0
        mean = ref.reshape(-1, 3).mean(axis=0)
        stderr = means.std(axis=0, ddof=1) / np.sqrt(a.passes) / mean
        file_depth, _ = render_passes(mi, path, 6, a.file_depth_spp, 4)
        file_mean = file_depth.reshape(-1, 3).mean(axis=0)
        bmp = mi.Bitmap(ref.astype(np.float32), pixel_format=mi.Bitmap.PixelFormat.RGB)
        bmp = bmp.convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float16, False)
        bmp.write(os.path.join(HERE, f"{name}.exr"))
        rec = {
            "scene": f"scenes/mitsuba-cbox/{name}.xml",
            "mitsuba": mi.__version__,
            "variant": mi.variant(),
            "integrator": "the file's path integrator, $max_depth = -1",
            "size": [int(ref.shape[1]), int(ref.shape[0])],
            "spp": a.spp,
            "passes": a.passes,
            "seconds": round(seconds, 1),
            "mean_rgb": [round(float(x), 7) for x in mean],
            "mean_rel_stderr": [round(float(x), 6) for x in stderr],
            "mean_rgb_file_max_depth": [round(float(x), 7) for x in file_mean],
            "file_max_depth": 6,
            "file_max_depth_spp": a.file_depth_spp,
            "command": "python3 scenes/mitsuba-cbox/make_references.py " + " ".join(sys.argv[1:]),
        }
        with open(os.path.join(HERE, f"{name}.json"), "w", encoding="utf-8") as f:
            json.dump(rec, f, indent=2)
            f.write("\n")
        print(json.dumps(rec))


if __name__ == "__main__":
    main()
