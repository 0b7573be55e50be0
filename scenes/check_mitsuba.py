#!/usr/bin/env python3
"""Check that every scene in scenes/ also loads in Mitsuba 3 (when installed).

Usage: python3 scenes/check_mitsuba.py [SCENE.xml ...]

For each scene it loads the file in the scalar_rgb and scalar_spectral
variants and prints what Mitsuba built (shape bounding boxes and areas,
the sensor's to_world and x field of view, the film size), so that trilux's
`trilux info` can be compared with it. Exits 0 when Mitsuba is missing
(this check is not required by CI), 1 when a scene fails to load.
"""
import glob
import os
import sys

try:
    import mitsuba as mi
except ImportError:
    print("mitsuba is not installed: skipping (pip install mitsuba)")
    sys.exit(0)

here = os.path.dirname(os.path.abspath(__file__))
scenes = sys.argv[1:] or sorted(glob.glob(os.path.join(here, "*.xml")))
failed = False
for variant in ("scalar_rgb", "scalar_spectral"):
    mi.set_variant(variant)
    for path in scenes:
        try:
            scene = mi.load_file(path)
        except Exception as e:  # noqa: BLE001 - report and go on
            print(f"FAIL {variant} {path}: {e}")
            failed = True
            continue
        print(f"ok   {variant} {os.path.basename(path)}: {len(scene.shapes())} shapes, "
              f"{len(scene.emitters())} emitters")
        if variant == "scalar_rgb":
            for s in scene.shapes():
                print(f"     shape {s.id():12s} area {s.surface_area():.6f} bbox {s.bbox()}".replace("\n", " "))
            for sensor in scene.sensors():
                params = mi.traverse(sensor)
                print(f"     sensor x_fov {params['x_fov']} film {sensor.film().size()}")
                print(f"     to_world {sensor.world_transform().matrix}".replace("\n", " "))
sys.exit(1 if failed else 0)
