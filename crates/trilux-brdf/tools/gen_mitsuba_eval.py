#!/usr/bin/env python3
"""Reference BRDF values from Mitsuba 3 for trilux-brdf's tests.

Run from the repository root (needs `pip install mitsuba`, variant scalar_rgb):

    python3 crates/trilux-brdf/tools/gen_mitsuba_eval.py > crates/trilux-brdf/tests/data/mitsuba_eval.json

For each material below, Mitsuba's `bsdf.eval(ctx, si, wo)` is called with
the viewer direction as `si.wi` and the light direction as `wo`, in a local
frame with z = the front normal. Mitsuba returns fr·|cosθ| of the light
direction; the file stores fr = eval / |cosθ_light|. The materials are
written twice: as Mitsuba XML (what Mitsuba loads) and as trilux's
`BsdfParams` in serde's JSON form (what the test builds), from one
description so the two cannot drift apart.
"""
import json
import math
import random
import sys

import mitsuba as mi

mi.set_variant("scalar_rgb")


# --- material descriptions -------------------------------------------------
def diffuse(refl):
    return ("diffuse", refl)


def conductor(dist, alpha, eta_k=None, spec=1.0):
    return ("roughconductor", dist, alpha, eta_k, spec)


def blend(w, a, b):
    return ("blend", w, a, b)


def twosided(front, back=None):
    return ("twosided", front, back)


def colour_xml(name, v):
    if isinstance(v, (list, tuple)):
        return f'<rgb name="{name}" value="{v[0]!r}, {v[1]!r}, {v[2]!r}"/>'
    return f'<float name="{name}" value="{v!r}"/>'


def colour_json(v):
    if isinstance(v, (list, tuple)):
        return {"Rgb": [float(x) for x in v]}
    return {"Float": float(v)}


def to_xml(m, top=True):
    ver = ' version="3.0.0"' if top else ""
    kind = m[0]
    if kind == "diffuse":
        return f'<bsdf{ver} type="diffuse">{colour_xml("reflectance", m[1])}</bsdf>'
    if kind == "roughconductor":
        _, dist, alpha, eta_k, spec = m
        inner = f'<string name="distribution" value="{dist}"/><float name="alpha" value="{alpha!r}"/>'
        if eta_k is None:
            inner += '<string name="material" value="none"/>'
        else:
            inner += colour_xml("eta", eta_k[0]) + colour_xml("k", eta_k[1])
        inner += colour_xml("specular_reflectance", spec)
        return f'<bsdf{ver} type="roughconductor">{inner}</bsdf>'
    if kind == "blend":
        _, w, a, b = m
        return (f'<bsdf{ver} type="blendbsdf"><float name="weight" value="{w!r}"/>'
                f'{to_xml(a, False)}{to_xml(b, False)}</bsdf>')
    if kind == "twosided":
        _, f, b = m
        inner = to_xml(f, False) + (to_xml(b, False) if b is not None else "")
        return f'<bsdf{ver} type="twosided">{inner}</bsdf>'
    raise ValueError(kind)


def to_json(m):
    kind = m[0]
    if kind == "diffuse":
        return {"Diffuse": {"reflectance": colour_json(m[1])}}
    if kind == "roughconductor":
        _, dist, alpha, eta_k, spec = m
        return {"RoughConductor": {
            "distribution": {"ggx": "Ggx", "beckmann": "Beckmann"}[dist],
            "alpha": float(alpha),
            "eta_k": None if eta_k is None else [colour_json(eta_k[0]), colour_json(eta_k[1])],
            "specular_reflectance": colour_json(spec),
        }}
    if kind == "blend":
        _, w, a, b = m
        return {"Blend": {"weight": float(w), "first": to_json(a), "second": to_json(b)}}
    if kind == "twosided":
        _, f, b = m
        return {"TwoSided": {"front": to_json(f), "back": None if b is None else to_json(b)}}
    raise ValueError(kind)


GOLD = ((0.143, 0.374, 1.442), (3.983, 2.385, 1.603))
CASES = [
    ("diffuse_rgb", diffuse((0.2, 0.5, 0.8))),
    ("ggx_0.01_none", conductor("ggx", 0.01)),
    ("ggx_0.05_none", conductor("ggx", 0.05)),
    ("ggx_0.3_none", conductor("ggx", 0.3)),
    ("ggx_1.0_none", conductor("ggx", 1.0)),
    ("beckmann_0.01_none", conductor("beckmann", 0.01)),
    ("beckmann_0.1_none", conductor("beckmann", 0.1)),
    ("beckmann_0.4_none", conductor("beckmann", 0.4)),
    ("beckmann_0.9_none", conductor("beckmann", 0.9)),
    ("ggx_0.2_gold_spec0.8", conductor("ggx", 0.2, GOLD, 0.8)),
    ("beckmann_0.3_float_eta_k", conductor("beckmann", 0.3, (1.5, 3.0), (0.9, 0.7, 0.5))),
    ("blend_0.3", blend(0.3, diffuse(0.6), conductor("ggx", 0.2))),
    ("blend_0.7_two_conductors", blend(0.7, conductor("beckmann", 0.5, GOLD), conductor("ggx", 0.08))),
    ("twosided_one", twosided(conductor("beckmann", 0.2))),
    ("twosided_two", twosided(diffuse((0.4, 0.3, 0.2)), conductor("ggx", 0.3, GOLD))),
]


def hemi(rng, zmin):
    z = rng.uniform(zmin, 1.0)
    phi = rng.uniform(0, 2 * math.pi)
    r = math.sqrt(max(0.0, 1 - z * z))
    return [r * math.cos(phi), r * math.sin(phi), z]


def normalize(v):
    n = math.sqrt(sum(c * c for c in v))
    return [c / n for c in v]


def directions(rng, two_sided):
    pairs = []
    for _ in range(24):  # generic
        pairs.append((hemi(rng, 0.05), hemi(rng, 0.05)))
    for _ in range(6):  # grazing
        pairs.append((hemi(rng, 0.0), normalize([1.0, 0.2, rng.uniform(0.002, 0.03)])))
    for _ in range(10):  # near the mirror direction
        wo = hemi(rng, 0.1)
        mirror = [-wo[0], -wo[1], wo[2]]
        d = [rng.gauss(0, 0.01) for _ in range(3)]
        wi = normalize([mirror[i] + d[i] for i in range(3)])
        if wi[2] > 0.01:
            pairs.append((wi, wo))
    if two_sided:
        for _ in range(10):  # back side
            a, b = hemi(rng, 0.05), hemi(rng, 0.05)
            pairs.append(([a[0], a[1], -a[2]], [b[0], b[1], -b[2]]))
    for _ in range(3):  # opposite sides: zero
        a, b = hemi(rng, 0.05), hemi(rng, 0.05)
        pairs.append(([a[0], a[1], -a[2]], b))
    return pairs


def main():
    rng = random.Random(20261121)
    ctx = mi.BSDFContext()
    out = {"generator": "crates/trilux-brdf/tools/gen_mitsuba_eval.py",
           "mitsuba_version": mi.__version__, "variant": "scalar_rgb",
           "convention": "local frame, z = front normal; wi towards the light, wo towards the viewer; fr without cosine",
           "cases": []}
    for name, m in CASES:
        xml = to_xml(m)
        bsdf = mi.load_string(xml)
        samples = []
        for wi, wo in directions(rng, m[0] == "twosided"):
            si = mi.SurfaceInteraction3f()
            si.p = mi.Point3f(0, 0, 0)
            si.n = mi.Normal3f(0, 0, 1)
            si.sh_frame = mi.Frame3f(mi.Vector3f(1, 0, 0), mi.Vector3f(0, 1, 0), mi.Vector3f(0, 0, 1))
            si.wi = mi.Vector3f(*wo)
            v = bsdf.eval(ctx, si, mi.Vector3f(*wi))
            c = abs(wi[2])
            fr = [float(v[k]) / c for k in range(3)]
            samples.append({"wi": wi, "wo": wo, "fr": fr})
        out["cases"].append({"name": name, "xml": xml, "params": to_json(m), "samples": samples})
    json.dump(out, sys.stdout, indent=1)
    sys.stdout.write("\n")


if __name__ == "__main__":
    main()
