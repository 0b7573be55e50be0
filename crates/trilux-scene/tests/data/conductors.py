#!/usr/bin/env python3
"""Mitsuba 3.9.1's smooth `conductor` and named conductor materials, for
crates/trilux-scene/tests/conductors.rs.

For each case, the <bsdf> as written and, variant scalar_rgb:
- a rough case (`roughconductor`): Mitsuba's `eval` divided by cos(theta_o)
  (the BRDF value fr) at fixed directions;
- a smooth case (`conductor`): Mitsuba's `sample` for each viewer
  direction (the mirror direction and its weight F * specular_reflectance;
  a Dirac lobe, so its eval is 0 everywhere).

Run from the repository root:
    python3 crates/trilux-scene/tests/data/conductors.py
writes crates/trilux-scene/tests/data/conductors.json.
"""
import json
import math
import os

import mitsuba as mi

mi.set_variant("scalar_rgb")

SMOOTH = [
    ("Cu", '<string name="material" value="Cu"/>'),
    ("Au, specular_reflectance", '<string name="material" value="Au"/>'
     '<rgb name="specular_reflectance" value="0.9, 0.8, 0.7"/>'),
    ("Ag", '<string name="material" value="Ag"/>'),
    ("Al", '<string name="material" value="Al"/>'),
    ("Cr", '<string name="material" value="Cr"/>'),
    ("W", '<string name="material" value="W"/>'),
    ("a-C", '<string name="material" value="a-C"/>'),
    ("TiO2-e_palik", '<string name="material" value="TiO2-e_palik"/>'),
    ("none", '<string name="material" value="none"/>'),
    ("default (none)", ''),
    ("rgb eta and k", '<rgb name="eta" value="0.2, 0.9, 1.1"/><rgb name="k" value="3.9, 2.4, 2.1"/>'),
    ("float eta, default k", '<float name="eta" value="1.5"/>'),
]

ROUGH = [
    ("Cu ggx 0.2", "ggx", 0.2, '<string name="material" value="Cu"/>'),
    ("Au beckmann 0.1", "beckmann", 0.1, '<string name="material" value="Au"/>'),
    ("Ag ggx 0.05", "ggx", 0.05, '<string name="material" value="Ag"/>'),
    ("Al beckmann 0.4", "beckmann", 0.4, '<string name="material" value="Al"/>'),
    ("Cr ggx 0.3, specular_reflectance", "ggx", 0.3,
     '<string name="material" value="Cr"/><float name="specular_reflectance" value="0.8"/>'),
    ("Ni_palik ggx 0.15", "ggx", 0.15, '<string name="material" value="Ni_palik"/>'),
    ("CuO beckmann 0.25", "beckmann", 0.25, '<string name="material" value="CuO"/>'),
]


def unit(v):
    n = math.sqrt(sum(c * c for c in v))
    return [c / n for c in v]


PAIRS = [
    (unit([0.3, 0.1, 0.95]), unit([-0.2, 0.4, 0.9])),
    (unit([0.0, 0.0, 1.0]), unit([0.1, -0.05, 1.0])),
    (unit([0.7, 0.2, 0.3]), unit([-0.6, -0.1, 0.5])),
    (unit([-0.4, 0.8, 0.45]), unit([0.35, -0.75, 0.5])),
    (unit([0.5, 0.0, 0.8]), unit([-0.52, 0.03, 0.79])),
]

VIEWERS = [unit([0.0, 0.0, 1.0]), unit([0.3, 0.1, 0.95]), unit([0.7, -0.2, 0.4]),
           unit([-0.9, 0.3, 0.12]), unit([0.2, 0.97, 0.05])]


def frame():
    si = mi.SurfaceInteraction3f()
    si.sh_frame = mi.Frame3f(mi.Vector3f(0, 0, 1))
    return si


def main():
    out = []
    for name, body in SMOOTH:
        xml = f'<bsdf version="3.0.0" type="conductor">{body}</bsdf>'
        bsdf = mi.load_string(xml)
        samples = []
        for wo in VIEWERS:
            si = frame()
            si.wi = mi.Vector3f(wo)
            bs, weight = bsdf.sample(mi.BSDFContext(), si, 0.5, mi.Point2f(0.3, 0.6))
            samples.append({"wo": wo, "wi": [float(bs.wo[c]) for c in range(3)],
                            "weight": [float(weight[c]) for c in range(3)],
                            "eval_off_mirror": [float(v) for v in bsdf.eval(
                                mi.BSDFContext(), si, mi.Vector3f(unit([-wo[0] + 0.05, -wo[1], wo[2] + 0.05])))]})
        out.append({"name": name, "plugin": "conductor", "body": body, "samples": samples})
    for name, distribution, alpha, body in ROUGH:
        inner = (f'<string name="distribution" value="{distribution}"/>'
                 f'<float name="alpha" value="{alpha}"/>{body}')
        xml = f'<bsdf version="3.0.0" type="roughconductor">{inner}</bsdf>'
        bsdf = mi.load_string(xml)
        samples = []
        for wi, wo in PAIRS:
            si = frame()
            si.wi = mi.Vector3f(wo)
            value = bsdf.eval(mi.BSDFContext(), si, mi.Vector3f(wi))
            samples.append({"wi": wi, "wo": wo,
                            "fr": [float(value[c]) / wi[2] for c in range(3)]})
        out.append({"name": name, "plugin": "roughconductor", "body": inner, "samples": samples})
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "conductors.json")
    with open(path, "w", encoding="utf-8") as f:
        json.dump({"mitsuba": mi.__version__, "variant": mi.variant(), "cases": out}, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
