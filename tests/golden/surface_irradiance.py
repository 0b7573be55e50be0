#!/usr/bin/env python3
"""Per-shape check of the solver against Mitsuba 3, without the renderer.

For every shape of a diffuse scene, Mitsuba 3's `irradiancemeter` (attached
to the shape, path tracer with unbounded depth) measures the mean irradiance
Ē over the shape's front face; the mean exitant reflected radiance of a
diffuse face is then ρ Ē / π, with ρ the face's RGB reflectance as Mitsuba
evaluates it (π fr at normal incidence). trilux's solve (RGB mode, the
example `surface_radiance`) gives the same number as the area mean of its
elements' reflected radiance. Their ratio per shape shows where the solver
gains or loses light.

    python3 tests/golden/surface_irradiance.py scenes/cornell-box.xml [--quality default] [--passes 16]
    python3 tests/golden/surface_irradiance.py scenes/cornell-box.xml --passes 8 \
        --write tests/golden/surfaces/cornell-box.json     # the reference of surface_means.rs

Needs Mitsuba 3 (`pip install mitsuba`); uses `llvm_ad_rgb` when LLVM is
available, else `scalar_rgb`.
"""
import argparse
import json
import os
import subprocess
import sys
import xml.etree.ElementTree as ET

import numpy as np
import mitsuba as mi

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)
from make_references import use_path_integrator  # noqa: E402


def set_variant():
    for v in ("llvm_ad_rgb", "scalar_rgb"):
        try:
            mi.set_variant(v)
            return v
        except Exception:
            pass
    raise SystemExit("no RGB variant of Mitsuba 3 available")


def metered_copy(path, spp, max_depth):
    """The scene with one irradiance meter per top-level shape that does not emit."""
    tree = ET.parse(path)
    root = tree.getroot()
    use_path_integrator(root, max_depth)
    shapes = [c for c in root if c.tag == "shape"]
    for i, shape in enumerate(shapes):
        if shape.find("emitter") is not None:
            continue  # an endpoint attaches to one shape: emitters are not metered
        sensor = ET.SubElement(shape, "sensor", {"type": "irradiancemeter", "id": f"meter_{i}"})
        film = ET.SubElement(sensor, "film", {"type": "hdrfilm"})
        ET.SubElement(film, "integer", {"name": "width", "value": "1"})
        ET.SubElement(film, "integer", {"name": "height", "value": "1"})
        ET.SubElement(film, "rfilter", {"type": "box"})
        sampler = ET.SubElement(sensor, "sampler", {"type": "independent"})
        ET.SubElement(sampler, "integer", {"name": "sample_count", "value": str(spp)})
        # A distinct seed per meter: Mitsuba's parser merges identical
        # declarations, and one sensor cannot attach to two shapes.
        ET.SubElement(sampler, "integer", {"name": "seed", "value": str(i)})
    out = os.path.join(os.path.dirname(os.path.abspath(path)), ".metered-" + os.path.basename(path))
    tree.write(out)
    return out, len(shapes)


def reflectance(shape):
    """π fr at normal incidence on the front face, as Mitsuba evaluates it."""
    si = mi.SurfaceInteraction3f()
    si.wi = mi.Vector3f(0, 0, 1)
    si.sh_frame = mi.Frame3f(mi.Vector3f(0, 0, 1))
    si.uv = mi.Point2f(0.5, 0.5)
    ctx = mi.BSDFContext()
    v = shape.bsdf().eval(ctx, si, mi.Vector3f(0, 0, 1))
    return np.array([float(np.array(v[c]).ravel()[0]) for c in range(3)]) * np.pi


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("scene")
    ap.add_argument("--quality", default="default")
    ap.add_argument("--convergence", default=None)
    ap.add_argument("--max-shots", default=None,
                    help="stop trilux after this many shots (1: direct light, with --max-depth 2)")
    ap.add_argument("--max-depth", type=int, default=-1, help="Mitsuba's path depth")
    ap.add_argument("--write", default=None,
                    help="also store Mitsuba's values as JSON (the reference of "
                         "crates/trilux-solver/tests/surface_means.rs)")
    ap.add_argument("--spp", type=int, default=1 << 22, help="samples per pass")
    ap.add_argument("--passes", type=int, default=16,
                    help="independent passes; their spread gives the standard error")
    args = ap.parse_args()

    cmd = ["cargo", "run", "-q", "--release", "-p", "trilux-solver", "--example",
           "surface_radiance", "--", args.scene, args.quality]
    cmd.append(args.convergence or "-")
    if args.max_shots:
        cmd.append(args.max_shots)
    trilux = json.loads(subprocess.run(cmd, cwd=ROOT, check=True, capture_output=True,
                                       text=True).stdout)

    variant = set_variant()
    copy, count = metered_copy(args.scene, args.spp, args.max_depth)
    try:
        scene = mi.load_file(copy)
    finally:
        os.remove(copy)
    meters = {s.id(): s for s in scene.sensors()}
    shapes = [s for s in scene.shapes()]
    print(f"Mitsuba {mi.__version__} {variant}, {args.passes} × {args.spp} spp per meter; "
          f"trilux {args.quality}, CR {trilux['convergence_ratio']:.4f}")
    print(f"{'shape':>5} {'area':>8} {'mitsuba ρĒ/π (RGB)':>30} {'trilux':>30}  ratio ± 1σ (Mitsuba's noise)")
    tot_m, tot_t = 0.0, 0.0
    stored = []
    for i in range(count):
        sensor = meters.get(f"meter_{i}")
        if sensor is None:
            continue
        shape = next(s for s in shapes if s.sensor() is not None and s.sensor().id() == f"meter_{i}")
        passes = np.array([
            np.array(mi.render(scene, sensor=sensor, spp=args.spp, seed=1000 * i + k)).reshape(-1)[:3]
            for k in range(args.passes)])
        img = passes.mean(axis=0)
        stderr = passes.sum(axis=1).std(ddof=1) / np.sqrt(args.passes) / passes.sum(axis=1).mean()
        rho = reflectance(shape)
        m = rho * img / np.pi
        t = np.array(trilux["shapes"][i]["radiance"])
        area = trilux["shapes"][i]["area"]
        stored.append({"shape": i, "radiance": [float(c) for c in m],
                       "relative_stderr": float(stderr)})
        tot_m += area * m.sum()
        tot_t += area * t.sum()
        ratio = t.sum() / m.sum() if m.sum() > 0 else float("nan")
        print(f"{i:>5} {area:8.4f} {np.array2string(m, precision=5):>30} "
              f"{np.array2string(t, precision=5):>30}  {ratio:.4f} ± {ratio * stderr:.4f}")
    print(f"area-weighted total ratio trilux/mitsuba: {tot_t / tot_m:.4f}")
    if args.write:
        with open(args.write, "w", encoding="utf-8") as f:
            json.dump({"scene": os.path.relpath(os.path.abspath(args.scene), ROOT),
                       "mitsuba": mi.__version__, "variant": variant,
                       "samples_per_pass": args.spp, "passes": args.passes,
                       "max_depth": args.max_depth,
                       "what": "mean reflected radiance rho*E/pi of each non-emitting "
                               "shape's front face (RGB)",
                       "shapes": stored}, f, indent=1)
            f.write("\n")


if __name__ == "__main__":
    sys.exit(main())
