#!/usr/bin/env python3
"""Mitsuba 3.9.1's smooth `conductor` with named materials in its spectral
variant (scalar_spectral), for crates/trilux-scene/tests/conductors.rs:
the weight of `sample` (F(lambda) for a mirror) at 9 wavelengths evenly
across each of trilux's 20 spectral bands (edges 360, then 400 + 15 b nm
for b = 1..19, then 830: trilux_color::bands::band_edge), for two viewer
directions.

Run from the repository root:
    python3 crates/trilux-scene/tests/data/conductors_spectral.py
writes crates/trilux-scene/tests/data/conductors_spectral.json.
"""
import json
import math
import os

import mitsuba as mi

mi.set_variant("scalar_spectral")

MATERIALS = ["Cu", "Au", "Ag", "Al", "Cr", "TiN"]
BANDS = 20
EDGES = [360.0] + [400.0 + 300.0 * b / BANDS for b in range(1, BANDS)] + [830.0]
PER_BAND = 9
VIEWERS = [[0.0, 0.0, 1.0], [0.6, 0.0, 0.8]]


def main():
    out = []
    for name in MATERIALS:
        bsdf = mi.load_string(f'<bsdf version="3.0.0" type="conductor">'
                              f'<string name="material" value="{name}"/></bsdf>')
        per_viewer = []
        for wo in VIEWERS:
            bands = []
            for b in range(BANDS):
                weights = []
                for j in range(PER_BAND):
                    lam = EDGES[b] + (EDGES[b + 1] - EDGES[b]) * j / (PER_BAND - 1)
                    si = mi.SurfaceInteraction3f()
                    si.sh_frame = mi.Frame3f(mi.Vector3f(0, 0, 1))
                    si.wi = mi.Vector3f(wo)
                    si.wavelengths = mi.Spectrum([lam] * 4)
                    _, w = bsdf.sample(mi.BSDFContext(), si, 0.5, mi.Point2f(0.5, 0.5))
                    # Mitsuba's F is NaN past a table's end (eta = k = 0
                    # there: TiN ends at 826.5 nm); such wavelengths are left out.
                    if math.isfinite(float(w[0])):
                        weights.append(float(w[0]))
                bands.append(weights)
            per_viewer.append({"wo": wo, "bands": bands})
        out.append({"material": name, "viewers": per_viewer})
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "conductors_spectral.json")
    with open(path, "w", encoding="utf-8") as f:
        json.dump({"mitsuba": mi.__version__, "variant": mi.variant(),
                   "band_edges_nm": EDGES, "cases": out}, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
