#!/usr/bin/env python3
"""Reference values of Mitsuba 3's `plastic` and `roughplastic` for
trilux-brdf's tests (crates/trilux-brdf/tests/mitsuba_plastic.rs).

Run from the repository root (needs `pip install mitsuba`, variant scalar_rgb):

    python3 crates/trilux-brdf/tools/gen_mitsuba_plastic.py > crates/trilux-brdf/tests/data/mitsuba_plastic.json

Each material is written as Mitsuba XML and as trilux's `BsdfParams` (serde
JSON) from one description. Local frame, z = front normal; Mitsuba's
`si.wi` is the viewer (trilux's `wo`), Mitsuba's `wo` the light (trilux's
`wi`). Stored per direction pair: fr = eval / |cosθ_light| and Mitsuba's
`pdf`. Stored per sample (sample1, sample2): Mitsuba's sampled light
direction, its pdf, its weight (eval·cos/pdf, or F/prob for the delta
lobe) and whether it is the delta lobe.
"""
import json
import math
import random
import sys

import mitsuba as mi

mi.set_variant("scalar_rgb")

# Mitsuba's IOR table entries used below (include/mitsuba/render/ior.h).
IOR = {"polypropylene": 1.49, "air": 1.000277, "bk7": 1.5046, "water": 1.3330}


def plastic(rough=None, diffuse=None, spec=None, int_ior=None, ext_ior=None, nonlinear=False):
    return dict(rough=rough, diffuse=diffuse, spec=spec, int_ior=int_ior,
                ext_ior=ext_ior, nonlinear=nonlinear)


def colour_xml(name, v):
    if isinstance(v, (list, tuple)):
        return f'<rgb name="{name}" value="{v[0]!r}, {v[1]!r}, {v[2]!r}"/>'
    return f'<float name="{name}" value="{v!r}"/>'


def colour_json(v):
    if isinstance(v, (list, tuple)):
        return {"Rgb": [float(x) for x in v]}
    return {"Float": float(v)}


def ior_xml(name, v):
    if isinstance(v, str):
        return f'<string name="{name}" value="{v}"/>'
    return f'<float name="{name}" value="{v!r}"/>'


def ior_value(v, default):
    if v is None:
        return IOR[default]
    return IOR[v] if isinstance(v, str) else float(v)


def to_xml(m, twosided=False):
    kind = "roughplastic" if m["rough"] else "plastic"
    inner = ""
    if m["rough"]:
        dist, alpha = m["rough"]
        inner += f'<string name="distribution" value="{dist}"/><float name="alpha" value="{alpha!r}"/>'
    if m["diffuse"] is not None:
        inner += colour_xml("diffuse_reflectance", m["diffuse"])
    if m["spec"] is not None:
        inner += colour_xml("specular_reflectance", m["spec"])
    if m["int_ior"] is not None:
        inner += ior_xml("int_ior", m["int_ior"])
    if m["ext_ior"] is not None:
        inner += ior_xml("ext_ior", m["ext_ior"])
    if m["nonlinear"]:
        inner += '<boolean name="nonlinear" value="true"/>'
    b = f'<bsdf type="{kind}">{inner}</bsdf>'
    if twosided:
        return f'<bsdf version="3.0.0" type="twosided">{b}</bsdf>'
    return b.replace("<bsdf ", '<bsdf version="3.0.0" ', 1)


def to_json(m, twosided=False):
    p = {"Plastic": {
        "diffuse_reflectance": colour_json(0.5 if m["diffuse"] is None else m["diffuse"]),
        "specular_reflectance": colour_json(1.0 if m["spec"] is None else m["spec"]),
        "int_ior": ior_value(m["int_ior"], "polypropylene"),
        "ext_ior": ior_value(m["ext_ior"], "air"),
        "nonlinear": m["nonlinear"],
        "coat": None if not m["rough"] else
        [{"ggx": "Ggx", "beckmann": "Beckmann"}[m["rough"][0]], float(m["rough"][1])],
    }}
    if twosided:
        return {"TwoSided": {"front": p, "back": None}}
    return p


CASES = [
    ("roughplastic_defaults", plastic(rough=("beckmann", 0.1)), False),
    ("roughplastic_beckmann_0.3_rgb", plastic(rough=("beckmann", 0.3), diffuse=(0.7, 0.4, 0.1)), False),
    ("roughplastic_ggx_0.2_bk7", plastic(rough=("ggx", 0.2), diffuse=0.8, int_ior="bk7"), False),
    ("roughplastic_ggx_0.05", plastic(rough=("ggx", 0.05), diffuse=(0.2, 0.5, 0.9)), False),
    ("roughplastic_ggx_0.5_nonlinear", plastic(rough=("ggx", 0.5), diffuse=(0.9, 0.6, 0.3), nonlinear=True), False),
    ("roughplastic_beckmann_0.15_spec_water", plastic(rough=("beckmann", 0.15), spec=0.7, int_ior=1.7, ext_ior="water"), False),
    ("roughplastic_twosided", plastic(rough=("ggx", 0.3), diffuse=0.6), True),
    ("plastic_defaults", plastic(), False),
    ("plastic_rgb_nonlinear", plastic(diffuse=(0.8, 0.3, 0.05), nonlinear=True), False),
    ("plastic_water_spec", plastic(diffuse=0.3, spec=0.6, int_ior="water"), False),
    ("plastic_twosided", plastic(diffuse=(0.1, 0.6, 0.2), int_ior=1.6), True),
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
    for _ in range(24):
        pairs.append((hemi(rng, 0.05), hemi(rng, 0.05)))
    for _ in range(6):  # grazing
        pairs.append((hemi(rng, 0.0), normalize([1.0, 0.2, rng.uniform(0.002, 0.03)])))
    for _ in range(10):  # near the mirror direction
        wo = hemi(rng, 0.1)
        d = [rng.gauss(0, 0.02) for _ in range(3)]
        wi = normalize([-wo[0] + d[0], -wo[1] + d[1], wo[2] + d[2]])
        if wi[2] > 0.01:
            pairs.append((wi, wo))
    if two_sided:
        for _ in range(8):
            a, b = hemi(rng, 0.05), hemi(rng, 0.05)
            pairs.append(([a[0], a[1], -a[2]], [b[0], b[1], -b[2]]))
    for _ in range(3):  # opposite sides: zero
        a, b = hemi(rng, 0.05), hemi(rng, 0.05)
        pairs.append(([a[0], a[1], -a[2]], b))
    return pairs


def interaction(viewer):
    si = mi.SurfaceInteraction3f()
    si.p = mi.Point3f(0, 0, 0)
    si.n = mi.Normal3f(0, 0, 1)
    si.sh_frame = mi.Frame3f(mi.Vector3f(1, 0, 0), mi.Vector3f(0, 1, 0), mi.Vector3f(0, 0, 1))
    si.wi = mi.Vector3f(*viewer)
    return si


def main():
    rng = random.Random(20261203)
    ctx = mi.BSDFContext()
    out = {"generator": "crates/trilux-brdf/tools/gen_mitsuba_plastic.py",
           "mitsuba_version": mi.__version__, "variant": "scalar_rgb",
           "convention": "local frame, z = front normal; wi towards the light, wo towards the viewer; fr without cosine",
           "cases": []}
    for name, m, two in CASES:
        xml = to_xml(m, two)
        bsdf = mi.load_string(xml)
        evals = []
        for wi, wo in directions(rng, two):
            si = interaction(wo)
            v = bsdf.eval(ctx, si, mi.Vector3f(*wi))
            pdf = float(bsdf.pdf(ctx, si, mi.Vector3f(*wi)))
            c = abs(wi[2])
            evals.append({"wi": wi, "wo": wo, "fr": [float(v[k]) / c for k in range(3)], "pdf": pdf})
        samples = []
        for _ in range(40):
            wo = hemi(rng, 0.05)
            s1, s2 = rng.random(), [rng.random(), rng.random()]
            bs, w = bsdf.sample(ctx, interaction(wo), s1, mi.Point2f(*s2))
            if float(bs.pdf) <= 0:
                continue
            delta = bool(mi.has_flag(bs.sampled_type, mi.BSDFFlags.Delta))
            samples.append({"wo": wo, "wi": [float(bs.wo[k]) for k in range(3)],
                            "pdf": float(bs.pdf), "weight": [float(w[k]) for k in range(3)],
                            "delta": delta})
        out["cases"].append({"name": name, "xml": xml, "params": to_json(m, two),
                             "evals": evals, "samples": samples})
    json.dump(out, sys.stdout, indent=1)
    sys.stdout.write("\n")


if __name__ == "__main__":
    main()
