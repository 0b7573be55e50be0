#!/usr/bin/env python3
"""Glossy lobes from wide to mirror: trilux against Mitsuba 3, swept over roughness.

Writes, into a temporary folder, the bundled glossy tube
(scenes/glossy-tube.xml) with its roughconductor's alpha replaced by each
value of --alphas, and a closed mirror cube (a roughconductor of alpha
1e-4, normals flipped to the inside) around a small sphere light. Each is
rendered by Mitsuba 3's path tracer (`path`, max_depth -1) and by trilux
(`trilux render`, --quality as given), at --res x --res, and the script
prints one table row per scene: both image means (all pixels, the three
channels), their ratio, the masked relative RMSE (pixels where an emitter
is directly visible, dilated by 1 px, left out, as `cargo xtask golden`
does) and trilux's solve and render seconds (from its --stats file).

Usage (from the repository root, after `cargo build --release`):
    python3 scripts/glossy_sweep.py                      # all scenes
    python3 scripts/glossy_sweep.py --alphas 0.01 --no-cube --res 32
    python3 scripts/glossy_sweep.py --write-scenes DIR   # only write the XML

Needs Mitsuba 3 (`pip install mitsuba==3.9.1`; the llvm_ad_rgb variant
wants `apt-get install libllvm19`, else scalar_rgb is used) and numpy.
--markdown prints the rows as a Markdown table (docs/results.md).
"""
import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
EXE = [os.path.join(ROOT, "target", "release", "trilux")]

CUBE = """<?xml version="1.0" encoding="utf-8"?>
<!-- A closed mirror cube (roughconductor, alpha 1e-4, normals flipped to
     the inside) of edge 2 m around a small sphere light; the camera is
     inside, looking at a corner. Renders in Mitsuba 3 as is. -->
<scene version="3.0.0">
    <default name="spp" value="64"/>
    <default name="res" value="64"/>
    <integrator type="path"/>
    <sensor type="perspective">
        <float name="fov" value="60"/>
        <transform name="to_world">
            <lookat origin="-0.4, -0.3, -0.5" target="1, 1, 1" up="0, 1, 0"/>
        </transform>
        <sampler type="independent">
            <integer name="sample_count" value="$spp"/>
        </sampler>
        <film type="hdrfilm">
            <integer name="width" value="$res"/>
            <integer name="height" value="$res"/>
        </film>
    </sensor>
    <bsdf type="roughconductor" id="mirror">
        <string name="distribution" value="ggx"/>
        <float name="alpha" value="0.0001"/>
        <string name="material" value="none"/>
        <rgb name="specular_reflectance" value="0.8, 0.8, 0.8"/>
    </bsdf>
    <bsdf type="diffuse" id="black">
        <rgb name="reflectance" value="0, 0, 0"/>
    </bsdf>
    <shape type="cube">
        <boolean name="flip_normals" value="true"/>
        <ref id="mirror"/>
    </shape>
    <shape type="sphere">
        <point name="center" x="0.3" y="0.2" z="0.1"/>
        <float name="radius" value="0.1"/>
        <ref id="black"/>
        <emitter type="area">
            <rgb name="radiance" value="5, 5, 5"/>
        </emitter>
    </shape>
</scene>
"""


def write_scenes(folder, alphas, cube):
    """The scene files, as (name, path) pairs."""
    with open(os.path.join(ROOT, "scenes", "glossy-tube.xml")) as f:
        tube = f.read()
    pattern = r'(<float name="alpha" value=")[^"]*(")'
    if len(re.findall(pattern, tube)) != 1:
        sys.exit("scenes/glossy-tube.xml: expected exactly one alpha")
    out = []
    for a in alphas:
        name = f"tube-alpha-{a:g}"
        path = os.path.join(folder, name + ".xml")
        with open(path, "w") as f:
            f.write(re.sub(pattern, rf"\g<1>{a:g}\g<2>", tube))
        out.append((name, path))
    if cube:
        path = os.path.join(folder, "mirror-cube.xml")
        with open(path, "w") as f:
            f.write(CUBE)
        out.append(("mirror-cube", path))
    return out


def mitsuba_render(path, res, spp):
    """(image as an HxWx3 array, emitter mask, seconds)."""
    import mitsuba as mi
    import numpy as np

    try:
        mi.set_variant("llvm_ad_rgb")
    except Exception:  # noqa: BLE001 - no LLVM: the slow variant
        mi.set_variant("scalar_rgb")
    t0 = time.time()
    scene = mi.load_file(path, res=res, spp=spp)
    img = np.array(mi.render(scene, spp=spp))[:, :, :3]
    seconds = time.time() - t0
    direct = mi.load_file(path, res=res, spp=64)
    direct_int = mi.load_dict({"type": "path", "max_depth": 1})
    emitted = np.array(mi.render(direct, integrator=direct_int, spp=64))[:, :, :3]
    mask = emitted.sum(axis=2) > 0
    grown = mask.copy()
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            grown |= np.roll(np.roll(mask, dy, axis=0), dx, axis=1)
    if grown.mean() > 0.5:
        grown[:] = False
    return img, grown, seconds


def trilux_render(path, res, spp, quality, folder, name, timeout):
    """(image, solve seconds, render seconds), or None on a timeout."""
    import numpy as np

    exe = EXE[0]
    exr = os.path.join(folder, name + ".trilux.exr")
    stats = os.path.join(folder, name + ".stats.json")
    cmd = [exe, "render", path, "-o", exr, "--stats", stats, "--width", str(res),
           "--height", str(res), "--spp", str(spp), "--quality", quality]
    try:
        subprocess.run(cmd, check=True, timeout=timeout, stdout=subprocess.DEVNULL,
                       stderr=subprocess.DEVNULL)
    except subprocess.TimeoutExpired:
        return None
    import mitsuba as mi

    img = np.array(mi.Bitmap(exr))[:, :, :3]
    with open(stats) as f:
        s = json.load(f)
    solve = s.get("solve", {}).get("solve_seconds", s.get("solve_seconds", float("nan")))
    return img, solve, s.get("render_seconds", float("nan"))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--alphas", type=float, nargs="*",
                    default=[1e-4, 0.01, 0.05, 0.1, 0.25, 1.0])
    ap.add_argument("--no-cube", action="store_true")
    ap.add_argument("--res", type=int, default=32)
    ap.add_argument("--spp", type=int, default=64, help="trilux samples per pixel")
    ap.add_argument("--mitsuba-spp", type=int, default=4096)
    ap.add_argument("--quality", default="default")
    ap.add_argument("--timeout", type=float, default=300.0, help="per trilux run, seconds")
    ap.add_argument("--trilux", metavar="EXE", help="the trilux binary (default: target/release)")
    ap.add_argument("--write-scenes", metavar="DIR")
    ap.add_argument("--markdown", action="store_true")
    args = ap.parse_args()
    if args.trilux:
        EXE[0] = args.trilux
    if args.write_scenes:
        os.makedirs(args.write_scenes, exist_ok=True)
        for name, path in write_scenes(args.write_scenes, args.alphas, not args.no_cube):
            print(name, path)
        return
    import numpy as np

    folder = tempfile.mkdtemp(prefix="glossy-sweep-")
    scenes = write_scenes(folder, args.alphas, not args.no_cube)
    if args.markdown:
        print("| scene | Mitsuba mean | trilux mean | ratio | masked relRMSE "
              "| solve s | render s |")
        print("|---|---|---|---|---|---|---|")
    for name, path in scenes:
        ref, mask, _ = mitsuba_render(path, args.res, args.mitsuba_spp)
        run = trilux_render(path, args.res, args.spp, args.quality, folder, name, args.timeout)
        if run is None:
            row = (name, ref.mean(), float("nan"), float("nan"), float("nan"),
                   float("inf"), float("nan"))
        else:
            img, solve, render = run
            keep = ~mask
            rel = np.sqrt(((img - ref)[keep] ** 2).sum() / (ref[keep] ** 2).sum())
            row = (name, ref.mean(), img.mean(), img.mean() / ref.mean(), rel, solve, render)
        if args.markdown:
            print("| {} | {:.4f} | {:.4f} | {:.3f} | {:.3f} | {:.1f} | {:.2f} |".format(*row))
        else:
            print("{:<18} mitsuba {:.4f} trilux {:.4f} ratio {:.3f} relRMSE {:.3f} "
                  "solve {:.1f} s render {:.2f} s".format(*row), flush=True)


if __name__ == "__main__":
    main()
