#!/usr/bin/env python3
"""The preview against the full render and the golden references.

For each scene: `trilux solve` (default quality), then from that one
solution `trilux render --preview` at 512 x 512 (its render seconds, from
--stats) and at 128 x 128, and the full render (the default estimator,
--spp samples a pixel) at 128 x 128. Prints one row per scene: the
preview's render seconds at 512, its mean over the full render's, and
its relative RMSE and mean ratio against the Mitsuba reference
(tests/golden/NAME.exr with its mask, as `cargo xtask golden compare`
computes them), and the full render's mean ratio against the reference.

Usage (from the repository root, after `cargo build --release -p trilux`):
    python3 scripts/preview_glossy.py [--trilux target/release/trilux]
        [--spp 64] [--out DIR] [--markdown] [SCENE ...]
SCENE a name under scenes/ without its extension (default: the glossy
golden scenes). Needs numpy and mitsuba (to read EXR files).
"""
import argparse
import json
import os
import subprocess

import mitsuba as mi
import numpy as np

mi.set_variant("scalar_rgb")

GLOSSY = [
    "glossy-tube", "paper-scene1", "paper-scene2", "paper-scene3",
    "crossing-room", "plastic-box", "textured-box", "textured-room",
    "product-shot", "boxes-64", "conductors/metal-box", "lights/point-glossy",
]


def scene_file(name):
    for ext in (".xml", ".gltf", ".glb"):
        path = os.path.join("scenes", name + ext)
        if os.path.exists(path):
            return path
    raise SystemExit(f"no scene file for {name}")


def read(path):
    return np.array(mi.Bitmap(path), dtype=np.float64)[..., :3]


def compare(image, reference, mask):
    """Relative RMSE and mean ratio over the pixels the mask leaves in
    (first channel <= 0.5: trilux_render::compare's definitions)."""
    k = image.shape[0] // reference.shape[0]
    if k > 1:  # a smaller reference: the image's k x k pixel means
        h, w = reference.shape[:2]
        image = image[:h * k, :w * k].reshape(h, k, w, k, 3).mean(axis=(1, 3))
    keep = mask[..., 0] <= 0.5 if mask is not None else np.ones(image.shape[:2], bool)
    a, r = image[keep], reference[keep]
    rel = np.sqrt(((a - r) ** 2).sum() / (r ** 2).sum())
    return rel, a.mean() / r.mean()


def run(cmd):
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--trilux", default="target/release/trilux")
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--out", default="out/preview-glossy")
    ap.add_argument("--markdown", action="store_true")
    ap.add_argument("scenes", nargs="*", default=GLOSSY)
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    rows = []
    for name in args.scenes:
        base = os.path.join(args.out, name.replace("/", "-"))
        src = scene_file(name)
        run([args.trilux, "solve", src, "-o", base + ".sol"])
        common = [args.trilux, "render", src, "--solution", base + ".sol"]
        run(common + ["--preview", "--width", "512", "--height", "512",
                      "-o", base + "-preview-512.exr", "--stats", base + "-preview-512.json"])
        with open(base + "-preview-512.json") as f:
            seconds = json.load(f)["render_seconds"]
        run(common + ["--preview", "--width", "128", "--height", "128",
                      "-o", base + "-preview-128.exr"])
        run(common + ["--spp", str(args.spp), "--width", "128", "--height", "128",
                      "-o", base + "-full-128.exr"])
        preview, full = read(base + "-preview-128.exr"), read(base + "-full-128.exr")
        # The golden reference, or the one beside the scene (scenes/lights,
        # scenes/conductors: unmasked).
        ref_path = os.path.join("tests", "golden", name + ".exr")
        if not os.path.exists(ref_path):
            ref_path = os.path.splitext(src)[0] + ".exr"
        mask_path = os.path.join("tests", "golden", name + ".mask.exr")
        mask = read(mask_path) if os.path.exists(mask_path) else None
        if os.path.exists(ref_path):
            ref = read(ref_path)
            rel, ratio = compare(preview, ref, mask)
            _, full_ratio = compare(full, ref, mask)
        else:
            rel = ratio = full_ratio = float("nan")
        rows.append((name, seconds, preview.mean() / full.mean(), rel, ratio, full_ratio))
    head = ("| scene | preview 512² render s | preview / full render (mean) "
            "| preview relRMSE vs reference | preview / reference | full / reference |")
    if args.markdown:
        print(head)
        print("|---|---|---|---|---|---|")
    for name, s, pf, rel, ratio, fr in rows:
        print(f"| {name} | {s:.2f} | {pf:.4f} | {rel:.4f} | {ratio:.4f} | {fr:.4f} |")


if __name__ == "__main__":
    main()
