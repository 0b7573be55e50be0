#!/usr/bin/env python3
"""colour-science side of `cargo xtask color`.

Reads a JSON list of spectra ({"name", "samples": [[nm, value], ...]}) from
the file named by argv[1]; writes, for each, CIE 1931 XYZ (equal-energy
spectrum → Y = 1) and linear and encoded sRGB as colour-science computes
them, as JSON on stdout.

Each spectrum is linear between its samples and zero outside (Mitsuba's and
trilux's rule); it is evaluated on the CIE 1 nm grid 360–830 nm here with
numpy, so colour-science is not asked to interpolate (its default
interpolators differ from the linear rule).
"""
import json
import sys
import warnings

warnings.filterwarnings("ignore")
import numpy as np  # noqa: E402
import colour  # noqa: E402


def main() -> None:
    spectra = json.load(open(sys.argv[1]))
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    wl = np.arange(360, 831, dtype=float)
    equal_energy = colour.SpectralDistribution(dict(zip(wl, np.ones_like(wl))))
    k = 1.0 / float(np.sum(cmfs.values[:, 1]))
    out = []
    for s in spectra:
        lam = np.array([p[0] for p in s["samples"]], dtype=float)
        val = np.array([p[1] for p in s["samples"]], dtype=float)
        v = np.interp(wl, lam, val, left=0.0, right=0.0)
        sd = colour.SpectralDistribution(dict(zip(wl, v)))
        # colour-science returns the 'Integration' result on a 0–1 scale
        # divided by 100 for a given k; undo that.
        xyz = colour.sd_to_XYZ(sd, cmfs=cmfs, illuminant=equal_energy, k=k, method="Integration") * 100.0
        lin = colour.XYZ_to_sRGB(xyz, apply_cctf_encoding=False)
        enc = colour.XYZ_to_sRGB(np.clip(xyz, 0, None), apply_cctf_encoding=True)
        out.append({"name": s["name"], "xyz": [float(c) for c in xyz],
                    "srgb_linear": [float(c) for c in lin], "srgb_encoded": [float(c) for c in enc]})
    json.dump({"colour_version": colour.__version__, "results": out}, sys.stdout)


if __name__ == "__main__":
    main()
