#!/usr/bin/env python3
"""Mitsuba 3.9.1's image means of the scenes lit by a `constant` sky in
tests/environment/ (courtyard.xml with the sky seen and with
`hide_emitters`; daylight-room.xml, a closed room lit through one window,
under the sky alone and with a sun; glazed-room.xml, the same room with a
pane of thin glass in the window, under the sky alone: Mitsuba's path
tracer cannot carry a delta sun through a delta pane),
for crates/trilux/tests/environment.rs.

Usage (from anywhere):
    python3 tests/environment/make_reference.py [--spp N] [--passes P]

Writes reference.json beside this script.
"""
import argparse
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
# The sun of the daylight room's sunlit case (its irradiance, W m^-2);
# crates/trilux/tests/environment.rs passes the same.
SUN = "40, 38, 34"
sys.path.insert(0, os.path.join(HERE, "..", "..", "scenes", "mitsuba-cbox"))
import image_means  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--spp", type=int, default=8192)
    ap.add_argument("--passes", type=int, default=8)
    a = ap.parse_args()
    import mitsuba as mi

    mi.set_variant("llvm_ad_rgb")
    cases = {}
    for name, file, params in (
        ("sky_seen", "courtyard.xml", {"hide": "false"}),
        ("sky_hidden", "courtyard.xml", {"hide": "true"}),
        ("daylight_room", "daylight-room.xml", {}),
        ("daylight_room_sun", "daylight-room.xml", {"sun": SUN}),
        ("glazed_room", "glazed-room.xml", {}),
    ):
        scene = mi.load_file(os.path.join(HERE, file), **params)
        mean, stderr = image_means.mean_over_passes(mi, scene, a.spp, a.passes)
        cases[name] = image_means.rounded(mean, stderr)
    image_means.write(
        os.path.join(HERE, "reference.json"),
        {
            "scenes": "tests/environment/{courtyard,daylight-room,glazed-room}.xml",
            "mitsuba": mi.__version__,
            "variant": mi.variant(),
            "spp": a.spp,
            "passes": a.passes,
            "cases": cases,
            "command": "python3 tests/environment/make_reference.py " + " ".join(sys.argv[1:]),
        },
    )


if __name__ == "__main__":
    main()
