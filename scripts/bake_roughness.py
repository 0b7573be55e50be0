#!/usr/bin/env python3
"""The directional bake's error by roughness: the viewer against trilux's full render.

Writes the bundled glossy tube (scenes/glossy-tube.xml) with its
roughconductor's alpha replaced by each value of --alphas into a temporary
folder; for each, `trilux solve`, `trilux render` (the full render, --spp
samples a pixel, PNG at --exposure), `trilux bake --glossy` of the same solution,
and the viewer's screenshots of the bake from the scene's camera in
headless Chromium (docs/viewer/test/screenshot.mjs): glossy light shown,
diffuse only (--glossy 0), and the mask of the glossy sides (--mask
glossy). Prints one row per alpha: the full render's and the viewer's
means over the whole picture and over the glossy sides, the gaps, the
relative RMSE over the glossy sides, the diffuse-only gap there (what the
bake left out before), and the bake's file size and glossy seconds.

Usage (from the repository root, after `cargo build --release -p trilux`
and `npm ci` in docs/viewer):
    python3 scripts/bake_roughness.py [--alphas 0.05 0.1 0.25 0.5] [--spp 64] [--markdown]
Needs numpy and Pillow.
"""
import argparse
import json
import os
import re
import subprocess
import tempfile

import numpy as np
from PIL import Image

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
EXE = os.path.join(ROOT, "target", "release", "trilux")
SHOT = os.path.join(ROOT, "docs", "viewer", "test", "screenshot.mjs")


def run(cmd):
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)


def png(path):
    return np.asarray(Image.open(path).convert("RGB"), dtype=float) / 255.0


def row(alpha, tmp, args):
    text = open(os.path.join(ROOT, "scenes", "glossy-tube.xml")).read()
    text, n = re.subn(r'(<float name="alpha" value=")[^"]*(")', rf"\g<1>{alpha}\g<2>", text)
    assert n == 1, "glossy-tube.xml has one alpha"
    stem = os.path.join(tmp, f"tube-{alpha}")
    xml = stem + ".xml"  # the tube refers to no other file
    open(xml, "w").write(text)
    run([EXE, "solve", xml, "-o", stem + ".sol"])
    run([EXE, "render", xml, "--solution", stem + ".sol", "--spp", str(args.spp),
         "-o", stem + "-full.exr", "--png", stem + "-full.png", "--exposure", str(args.exposure)])
    run([EXE, "bake", xml, "--glossy", "--solution", stem + ".sol", "-o", stem + ".glb", "--stats", stem + ".json"])
    full = png(stem + "-full.png")
    h, w = full.shape[:2]
    shots = {}
    for name, extra in [("viewer", []), ("diffuse", ["--glossy", "0"]), ("mask", ["--mask", "glossy"])]:
        out = f"{stem}-{name}.png"
        run(["node", SHOT, "--glb", stem + ".glb", "--width", str(w), "--height", str(h),
             "--out", out, "--exposure", str(args.exposure)] + extra)
        shots[name] = png(out)
    mask = shots["mask"].min(axis=2) > 0.5
    stats = json.load(open(stem + ".json"))["bake"]
    m = lambda a, sel=None: float(a[sel].mean()) if sel is not None else float(a.mean())
    fm, vm, dm = m(full, mask), m(shots["viewer"], mask), m(shots["diffuse"], mask)
    rmse = float(np.sqrt(((full[mask] - shots["viewer"][mask]) ** 2).mean())) / fm
    return {
        "alpha": alpha, "full": m(full), "viewer": m(shots["viewer"]),
        "gap": m(shots["viewer"]) / m(full) - 1, "full_glossy": fm, "viewer_glossy": vm,
        "glossy_gap": vm / fm - 1, "glossy_rel_rmse": rmse, "diffuse_only_gap": dm / fm - 1,
        "mb": stats["bytes"] / 1e6, "vertices": stats["vertices"],
        "glossy_seconds": stats.get("glossy_seconds", float("nan")),
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--alphas", type=float, nargs="+", default=[0.05, 0.1, 0.25, 0.5])
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--exposure", type=float, default=-1.5)
    ap.add_argument("--markdown", action="store_true")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        rows = [row(a, tmp, args) for a in args.alphas]
    if args.markdown:
        print("| GGX α | full mean | viewer mean | gap | glossy sides: full | viewer | gap | rel. RMSE | diffuse-only gap | file MB | glossy s |")
        print("|---|---|---|---|---|---|---|---|---|---|---|")
        for r in rows:
            print(f"| {r['alpha']} | {r['full']:.4f} | {r['viewer']:.4f} | {100 * r['gap']:+.2f} % | "
                  f"{r['full_glossy']:.4f} | {r['viewer_glossy']:.4f} | {100 * r['glossy_gap']:+.2f} % | "
                  f"{r['glossy_rel_rmse']:.3f} | {100 * r['diffuse_only_gap']:+.2f} % | {r['mb']:.2f} | {r['glossy_seconds']:.2f} |")
    else:
        for r in rows:
            print(json.dumps(r))


if __name__ == "__main__":
    main()
