#!/usr/bin/env python3
"""Mitsuba 3.9.1 image means of cbox.xml (spectral) seen through a sensor
spectral response (`srf`), at the file's own max_depth 6.

Usage (from anywhere):
    python3 scenes/mitsuba-cbox/make_srf_references.py [--spp N] [--passes K]

Each case inserts `<spectrum name="srf" value="..."/>` as the first child
of the file's <sensor> (nothing else changes) and renders N samples per
pixel in K passes with seeds 0..K-1 (llvm_ad_spectral, else
scalar_spectral: Mitsuba reads srf in spectral variants only). Writes
srf.json beside this script: per case the srf, the per-channel image mean
and its relative standard error (the passes' spread / sqrt(K) / |mean|).
"""
import argparse
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from image_means import mean_over_passes, rounded, write  # noqa: E402

CASES = {
    "red_box": "600:1, 700:1",
    "ramp": "400:0.5, 700:1.5",
}


def with_srf(srf):
    text = open(os.path.join(HERE, "cbox.xml"), encoding="utf-8").read()
    at = text.index(">", text.index("<sensor")) + 1
    return text[:at] + f'\n<spectrum name="srf" value="{srf}"/>' + text[at:]


def case_mean(mi, srf, spp, passes):
    return mean_over_passes(mi, mi.load_string(with_srf(srf)), spp, passes)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--passes", type=int, default=8)
    a = ap.parse_args()
    import mitsuba as mi

    try:
        mi.set_variant("llvm_ad_spectral")
    except Exception as e:  # noqa: BLE001 - fall back, and say so
        print(f"llvm_ad_spectral unavailable ({e}); using scalar_spectral")
        mi.set_variant("scalar_spectral")
    mi.Thread.thread().file_resolver().prepend(HERE)
    rec = {"scene": "scenes/mitsuba-cbox/cbox.xml", "mitsuba": mi.__version__,
           "variant": mi.variant(), "spp": a.spp, "passes": a.passes, "cases": {}}
    for name, srf in CASES.items():
        mean, stderr = case_mean(mi, srf, a.spp, a.passes)
        rec["cases"][name] = {"srf": srf, **rounded(mean, stderr)}
    rec["command"] = "python3 scenes/mitsuba-cbox/make_srf_references.py " + " ".join(sys.argv[1:])
    write(os.path.join(HERE, "srf.json"), rec)


if __name__ == "__main__":
    main()
