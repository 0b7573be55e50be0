#!/usr/bin/env python3
"""Mitsuba 3.9.1's `thindielectric` and `mask` (scalar_rgb) sampled at
chosen angles, for crates/trilux-scene/tests/thindielectric.rs.

Each case is a `<bsdf>` body; at each |cos theta| (from the front and from
the back) Mitsuba's `sample` is asked twice: with sample1 = 0 (it picks the
reflection, with probability R) and with sample1 = 1 - 1e-6 (the
transmission, probability T = 1 - R). Stored: R = the reflection's pdf,
times its weight (specular_reflectance), and T = the transmission's pdf
times its weight (specular_transmittance; 0 where Mitsuba picks the
reflection even then: total internal reflection), and whether the
transmitted direction is -wi (straight through).

For each `mask` case: `eval` at direction pairs (fr = eval / |cos| of the
light direction; "wi" towards the light, "wo" towards the viewer), and the
fraction let through, straight on: the pdf times the weight of the sample
that passes (sample1 = 1 - 1e-6, Mitsuba's null lobe).

Usage: python3 crates/trilux-scene/tests/data/thindielectric.py
       > crates/trilux-scene/tests/data/thindielectric.json
"""
import json
import math
import sys

import mitsuba as mi

mi.set_variant("scalar_rgb")

CASES = [
    ("defaults", ""),
    ("bk7_named", '<string name="int_ior" value="bk7"/>'),
    ("water_in_air", '<string name="int_ior" value="water"/><string name="ext_ior" value="air"/>'),
    ("float_1.7", '<float name="int_ior" value="1.7"/><float name="ext_ior" value="1.0"/>'),
    ("diamond_in_water", '<string name="int_ior" value="diamond"/><string name="ext_ior" value="water"/>'),
    ("scaled", '<float name="specular_reflectance" value="0.6"/><float name="specular_transmittance" value="0.8"/>'),
    ("below_one", '<float name="int_ior" value="1.0"/><float name="ext_ior" value="1.33"/>'),
]

COSINES = [1.0, 0.95, 0.8, 0.6, 0.45, 0.3, 0.2, 0.1, 0.05, 0.01]


MASKS = [
    ("mask_diffuse", '<float name="opacity" value="0.3"/><bsdf type="diffuse"><float name="reflectance" value="0.6"/></bsdf>'),
    ("mask_default_rgb", '<bsdf type="diffuse"><rgb name="reflectance" value="0.2, 0.5, 0.8"/></bsdf>'),
    ("mask_twosided_conductor", '<float name="opacity" value="0.8"/><bsdf type="twosided"><bsdf type="roughconductor"><float name="alpha" value="0.3"/></bsdf></bsdf>'),
]

PAIRS = [
    ([0.0, 0.6, 0.8], [0.3, 0.2, 0.9327379]),
    ([0.5, -0.1, 0.8602325], [-0.4, 0.1, 0.9110434]),
    ([0.7, 0.0, 0.7141428], [-0.7, 0.05, 0.7123202]),
    ([0.2, 0.3, -0.9327379], [0.1, -0.4, -0.9110434]),
    ([0.9, 0.1, 0.4242641], [0.0, 0.0, 1.0]),
]


def masks(ctx):
    out = []
    for name, body in MASKS:
        xml = '<bsdf version="3.0.0" type="mask">' + body + "</bsdf>"
        bsdf = mi.load_string(xml)
        evals = []
        for wi, wo in PAIRS:
            v = bsdf.eval(ctx, interaction(wo), mi.Vector3f(*wi))
            evals.append({"wi": wi, "wo": wo, "fr": [float(v[k]) / abs(wi[2]) for k in range(3)]})
        wo = PAIRS[0][1]
        bs, w = bsdf.sample(ctx, interaction(wo), 1.0 - 1e-6, mi.Point2f(0.5, 0.5))
        straight = all(abs(float(bs.wo[k]) + wo[k]) < 1e-6 for k in range(3))
        out.append({"name": name, "body": body, "evals": evals,
                    "t": float(bs.pdf) * float(w[0]), "straight": straight})
    return out


def interaction(wi):
    si = mi.SurfaceInteraction3f()
    si.p = mi.Point3f(0, 0, 0)
    si.n = mi.Normal3f(0, 0, 1)
    si.sh_frame = mi.Frame3f(mi.Vector3f(1, 0, 0), mi.Vector3f(0, 1, 0), mi.Vector3f(0, 0, 1))
    si.wi = mi.Vector3f(*wi)
    return si


def main():
    ctx = mi.BSDFContext()
    out = {"generator": "crates/trilux-scene/tests/data/thindielectric.py",
           "mitsuba_version": mi.__version__, "variant": "scalar_rgb", "cases": []}
    for name, body in CASES:
        xml = '<bsdf version="3.0.0" type="thindielectric">' + body + "</bsdf>"
        bsdf = mi.load_string(xml)
        rows = []
        for c in COSINES:
            for side in (1.0, -1.0):
                s = math.sqrt(max(0.0, 1.0 - c * c))
                wi = [s * 0.6, s * 0.8, side * c]
                si = interaction(wi)
                br, wr = bsdf.sample(ctx, si, 0.0, mi.Point2f(0.5, 0.5))
                bt, wt = bsdf.sample(ctx, si, 1.0 - 1e-6, mi.Point2f(0.5, 0.5))
                through = mi.has_flag(bt.sampled_type, mi.BSDFFlags.Transmission)
                straight = all(abs(float(bt.wo[k]) + wi[k]) < 1e-6 for k in range(3))
                rows.append({"cos": c, "side": side,
                             "r": float(br.pdf) * float(wr[0]),
                             "t": float(bt.pdf) * float(wt[0]) if through else 0.0,
                             "straight": straight or not through})
        out["cases"].append({"name": name, "body": body, "rows": rows})
    out["masks"] = masks(ctx)
    json.dump(out, sys.stdout, indent=1)
    sys.stdout.write("\n")


if __name__ == "__main__":
    main()
