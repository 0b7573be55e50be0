#!/usr/bin/env python3
"""Mitsuba 3.9.1's roughconductor with negative eta / k, for
crates/trilux-scene/tests/negative_ior.rs.

Mitsuba takes negative values (published optical data have them) and its
Fresnel term sees only eta^2, k^2 and eta^2 k^2; a <spectrum> of
wavelength:value pairs is first converted to RGB in the RGB variants, with
negative channels clamped to 0. This writes, for each case, the <bsdf> body
as written and Mitsuba's `eval` divided by cos(theta_o) at fixed directions
(the BRDF value fr), variant scalar_rgb.

Run from the repository root:
    python3 crates/trilux-scene/tests/data/negative_ior.py
writes crates/trilux-scene/tests/data/negative_ior.json.
"""
import json
import math
import os

import mitsuba as mi

mi.set_variant("scalar_rgb")

CASES = [
    ("rgb eta and k, mixed signs", "beckmann", 0.3,
     '<rgb name="eta" value="-0.2, 0.9, -1.5"/><rgb name="k" value="-3.1, 2.5, -0.4"/>'),
    ("negative float eta, default k", "ggx", 0.2,
     '<float name="eta" value="-0.5"/>'),
    ("uniform spectrum k", "ggx", 0.15,
     '<float name="eta" value="1.5"/><spectrum name="k" value="-2"/>'),
    ("one-value rgb eta", "beckmann", 0.5,
     '<rgb name="eta" value="-1.2"/><rgb name="k" value="2.2, -3.3, 4.4"/>'),
    ("sampled eta, all negative", "ggx", 0.25,
     '<spectrum name="eta" value="400:-0.5, 500:-1.0, 600:-1.5, 700:-0.2"/><float name="k" value="3"/>'),
    ("sampled eta, mixed signs", "beckmann", 0.4,
     '<spectrum name="eta" value="400:-0.5, 500:1.0, 600:-1.5, 700:0.2"/><float name="k" value="2"/>'),
]


def unit(v):
    n = math.sqrt(sum(c * c for c in v))
    return [c / n for c in v]


DIRECTIONS = [
    (unit([0.3, 0.1, 0.95]), unit([-0.2, 0.4, 0.9])),
    (unit([0.0, 0.0, 1.0]), unit([0.1, -0.05, 1.0])),
    (unit([0.7, 0.2, 0.3]), unit([-0.6, -0.1, 0.5])),
    (unit([-0.4, 0.8, 0.45]), unit([0.35, -0.75, 0.5])),
]


def main():
    out = []
    for name, distribution, alpha, body in CASES:
        xml = (f'<bsdf version="3.0.0" type="roughconductor">'
               f'<string name="distribution" value="{distribution}"/>'
               f'<float name="alpha" value="{alpha}"/>{body}</bsdf>')
        bsdf = mi.load_string(xml)
        samples = []
        for wi, wo in DIRECTIONS:
            si = mi.SurfaceInteraction3f()
            si.wi = mi.Vector3f(wi)
            si.sh_frame = mi.Frame3f(mi.Vector3f(0, 0, 1))
            value = bsdf.eval(mi.BSDFContext(), si, mi.Vector3f(wo))
            fr = [float(value[c]) / wo[2] for c in range(3)]
            samples.append({"wi": wi, "wo": wo, "fr": fr})
        out.append({"name": name, "distribution": distribution, "alpha": alpha,
                    "body": body, "samples": samples})
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "negative_ior.json")
    with open(path, "w", encoding="utf-8") as f:
        json.dump({"mitsuba": mi.__version__, "variant": mi.variant(), "cases": out}, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
