#!/usr/bin/env python3
"""Reference images for trilux's golden tests, rendered with Mitsuba 3.

For every scene file in scenes/ (or those named with --only), this renders
with Mitsuba 3's path tracer (`path`, max_depth -1: paths of unbounded
length, Russian roulette from depth 5, as trilux's solution has every
bounce) at a small fixed resolution, and writes into tests/golden/:

  NAME.exr        linear sRGB float32 RGB, the mean of PASSES passes of
                  PASS_SPP samples per pixel with seeds 0..PASSES-1
                  (the film's own reconstruction filter, Gaussian by default)
  NAME.mask.exr   1 where an emitter is directly visible in the pixel or
                  within 1 px of it (from a render of emitted radiance only,
                  max_depth 1, same filter), else 0: the golden comparison
                  may leave these pixels out. When emitters cover more than
                  half of the image (the furnace), nothing is masked.
  NAME.json       how the reference was made (Mitsuba version, variant, spp,
                  size, seconds) and its own noise: the relative RMSE
                  (definition below) between the means of the even and the
                  odd passes, halved = the estimated relative RMSE of the
                  reference itself against the converged image

Relative RMSE, the definition used here and by `cargo xtask golden`:
    relRMSE(a, r) = sqrt( sum_{pixels p not masked, channels c} (a_pc - r_pc)^2
                        / sum_{pixels p not masked, channels c} r_pc^2 )
(the RMS error normalised by the RMS of the reference).

glTF scenes (scenes/NAME.gltf, scenes/NAME.glb) are first converted by
scripts/gltf_to_mitsuba.py (the mapping trilux uses, docs/gltf.md) into a
temporary folder, and that Mitsuba scene is rendered.

Variant: `llvm_ad_spectral` when the scene has a <spectrum> with
wavelength:value pairs (the scene is spectral in trilux too: README, "Scene format"),
else `llvm_ad_rgb`. Both output linear sRGB.

The film size and the integrator are replaced in a temporary copy of the
scene written beside it (so that relative OBJ paths resolve), removed after.

Run from the repository root:
    python3 tests/golden/make_references.py                 # every scene
    python3 tests/golden/make_references.py --only cornell-box --spp 4096
    python3 tests/golden/make_references.py --max-depth 2 --res 64 --spp 8192 \
        --out tests/golden/direct        # direct light only, for trilux-render's tests
Needs Mitsuba 3 (`pip install mitsuba`) and, for the llvm variants, LLVM
(Debian: `apt-get install libllvm19`).
"""
import argparse
import glob
import json
import os
import re
import sys
import time
import xml.etree.ElementTree as ET

import numpy as np
import mitsuba as mi

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))


def is_spectral(path):
    text = open(path, encoding="utf-8").read()
    for m in re.finditer(r"<spectrum\b[^>]*\bvalue\s*=\s*\"([^\"]*)\"", text):
        if ":" in m.group(1):
            return True
    return False


def use_path_integrator(root, max_depth):
    """Replaces the scene's integrators by Mitsuba's `path` with `max_depth`."""
    for integ in root.findall("integrator"):
        root.remove(integ)
    integ = ET.SubElement(root, "integrator", {"type": "path"})
    ET.SubElement(integ, "integer", {"name": "max_depth", "value": str(max_depth)})


def prepared_copy(path, res, max_depth):
    """A copy of the scene with the film size and the integrator replaced."""
    tree = ET.parse(path)
    root = tree.getroot()
    use_path_integrator(root, max_depth)
    sensor = root.find("sensor")
    if sensor is None:
        raise SystemExit(f"{path}: no <sensor>")
    film = sensor.find("film")
    if film is None:
        film = ET.SubElement(sensor, "film", {"type": "hdrfilm"})
    for name in ("width", "height"):
        el = [e for e in film.findall("integer") if e.get("name") == name]
        if el:
            el[0].set("value", str(res))
        else:
            ET.SubElement(film, "integer", {"name": name, "value": str(res)})
    out = os.path.join(os.path.dirname(path), f".ref-{os.getpid()}-{os.path.basename(path)}")
    tree.write(out, encoding="utf-8", xml_declaration=True)
    return out


def load(path, res, max_depth):
    tmp = prepared_copy(path, res, max_depth)
    try:
        return mi.load_file(tmp)
    finally:
        os.remove(tmp)


def rel_rmse(a, r, keep):
    d = ((a - r) ** 2)[keep].sum()
    n = (r ** 2)[keep].sum()
    return float(np.sqrt(d / n)) if n > 0 else float("nan")


def write_exr(path, arr):
    tmp = path + ".tmp.exr"
    mi.Bitmap(np.ascontiguousarray(arr, dtype=np.float32)).write(tmp)
    os.replace(tmp, path)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scenes", default=os.path.join(ROOT, "scenes"))
    ap.add_argument("--out", default=HERE)
    ap.add_argument("--only", action="append", help="scene name without .xml (repeatable)")
    ap.add_argument("--res", type=int, default=128)
    ap.add_argument("--spp", type=int, default=16384, help="total samples per pixel")
    ap.add_argument("--pass-spp", type=int, default=256)
    ap.add_argument("--mask-spp", type=int, default=256)
    ap.add_argument("--max-depth", type=int, default=-1,
                    help="path length limit: -1 unbounded (golden references); 2 = emission "
                         "and direct light only (tests/golden/direct/, for the renderer's "
                         "test with a solution that knows no indirect light)")
    args = ap.parse_args()
    if args.spp % args.pass_spp or (args.spp // args.pass_spp) % 2:
        raise SystemExit("--spp must be an even multiple of --pass-spp")
    passes = args.spp // args.pass_spp

    paths = sorted(p for ext in ("xml", "gltf", "glb")
                   for p in glob.glob(os.path.join(args.scenes, f"*.{ext}")))
    if args.only:
        paths = [p for p in paths if os.path.splitext(os.path.basename(p))[0] in args.only]
    for source in paths:
        name, ext = os.path.splitext(os.path.basename(source))
        path = source
        if ext in (".gltf", ".glb"):
            sys.path.insert(0, os.path.join(ROOT, "scripts"))
            import tempfile
            import gltf_to_mitsuba
            mi.set_variant("scalar_rgb")
            path = gltf_to_mitsuba.convert(source, tempfile.mkdtemp(prefix=f"trilux-{name}-"))
        variant = "llvm_ad_spectral" if is_spectral(path) else "llvm_ad_rgb"
        mi.set_variant(variant)
        print(f"{name}: {variant}, {args.res}x{args.res}, {args.spp} spp", flush=True)
        t0 = time.time()
        scene = load(path, args.res, args.max_depth)
        even = np.zeros((args.res, args.res, 3))
        odd = np.zeros_like(even)
        for k in range(passes):
            img = np.array(mi.render(scene, spp=args.pass_spp, seed=k))[:, :, :3]
            (even if k % 2 == 0 else odd)[...] += img
        seconds = time.time() - t0
        even /= passes // 2
        odd /= passes // 2
        ref = 0.5 * (even + odd)

        direct = np.array(mi.render(load(path, args.res, 1), spp=args.mask_spp, seed=0))[:, :, :3]
        hit = (direct > 0).any(axis=2)
        mask = hit.copy()
        for dy in (-1, 0, 1):
            for dx in (-1, 0, 1):
                mask |= np.roll(np.roll(hit, dy, axis=0), dx, axis=1)
        # Where emitters fill most of the view (the furnace: every wall
        # emits), masking would leave nothing to compare: mask nothing.
        mask_disabled = bool(mask.mean() > 0.5)
        if mask_disabled:
            mask[...] = False
        keep = np.repeat(~mask[:, :, None], 3, axis=2)

        write_exr(os.path.join(args.out, f"{name}.exr"), ref)
        write_exr(os.path.join(args.out, f"{name}.mask.exr"),
                  np.repeat(mask[:, :, None].astype(np.float32), 3, axis=2))
        info = {
            "scene": f"scenes/{name}{ext}",
            "mitsuba": mi.__version__,
            "variant": variant,
            "integrator": f"path, max_depth {args.max_depth}",
            "width": args.res,
            "height": args.res,
            "spp": args.spp,
            "passes": passes,
            "seconds": round(seconds, 2),
            "mean_rgb": [float(v) for v in ref.reshape(-1, 3).mean(axis=0)],
            "mean_rgb_unmasked": [float(v) for v in ref[~mask].mean(axis=0)],
            "masked_pixels": int(mask.sum()),
            "mask_disabled": mask_disabled,
            "noise_rel_rmse_unmasked": rel_rmse(even, odd, keep) / 2.0,
            "noise_rel_rmse_all": rel_rmse(even, odd, np.ones_like(keep)) / 2.0,
            "command": "python3 tests/golden/make_references.py " + " ".join(sys.argv[1:]),
        }
        with open(os.path.join(args.out, f"{name}.json"), "w") as f:
            json.dump(info, f, indent=2)
            f.write("\n")
        print(f"  {seconds:.1f} s, mean {info['mean_rgb']}, noise relRMSE "
              f"{info['noise_rel_rmse_unmasked']:.4f}, {info['masked_pixels']} masked", flush=True)


if __name__ == "__main__":
    main()
