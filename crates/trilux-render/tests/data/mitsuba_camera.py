#!/usr/bin/env python3
"""Reference camera rays from Mitsuba 3's `perspective` sensor.

Writes mitsuba_camera.txt next to this script. For several cameras (fov,
fov_axis, film size, lookat) it records the ray Mitsuba's
`sensor.sample_ray` returns for a grid of film positions (position sample in
[0,1]^2, (0,0) = top-left corner of the film). trilux-render's camera test
reads the file and must reproduce origin and direction to 1e-6.

Format, one line per ray:
    cam <i> fov <deg> axis <x|y|smaller|larger|diagonal> w <W> h <H>
        origin ox oy oz target tx ty tz up ux uy uz          (camera lines)
    ray <i> sx sy  ox oy oz  dx dy dz                          (ray lines)

Run: python3 mitsuba_camera.py   (needs `pip install mitsuba`, 3.x)
"""
import os
import mitsuba as mi

mi.set_variant("scalar_rgb")

CAMERAS = [
    # fov, axis, w, h, origin, target, up
    (39.3077, "x", 64, 48, (278, 273, -800), (278, 273, -799), (0, 1, 0)),
    (45.0, "y", 64, 48, (1, 2, 3), (0, 0.5, -1), (0, 1, 0)),
    (60.0, "smaller", 40, 80, (0, 0, 5), (0, 0, 0), (0, 1, 0)),
    (60.0, "smaller", 80, 40, (0, 0, 5), (0, 0, 0), (0, 1, 0)),
    (30.0, "larger", 40, 80, (-2, 1, 0.5), (3, 0, 1), (0, 0, 1)),
    (30.0, "larger", 80, 40, (-2, 1, 0.5), (3, 0, 1), (0, 0, 1)),
    (70.0, "diagonal", 100, 30, (0.3, -4, 1), (0, 0, 1), (0, 0, 1)),
    (20.0, "x", 16, 16, (0, 0, 0), (0, 0, 1), (1, 1, 0)),
]

POSITIONS = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0), (0.5, 0.5),
             (0.25, 0.75), (0.9, 0.1), (0.3, 0.6)]

here = os.path.dirname(os.path.abspath(__file__))
lines = [f"# made by mitsuba_camera.py with Mitsuba {mi.__version__} (scalar_rgb)"]
for i, (fov, axis, w, h, o, t, u) in enumerate(CAMERAS):
    sensor = mi.load_dict({
        "type": "perspective",
        "fov": fov,
        "fov_axis": axis,
        "to_world": mi.ScalarTransform4f().look_at(origin=o, target=t, up=u),
        "film": {"type": "hdrfilm", "width": w, "height": h},
    })
    lines.append(
        f"cam {i} fov {fov!r} axis {axis} w {w} h {h} origin {o[0]!r} {o[1]!r} {o[2]!r} "
        f"target {t[0]!r} {t[1]!r} {t[2]!r} up {u[0]!r} {u[1]!r} {u[2]!r}")
    for sx, sy in POSITIONS:
        ray, _ = sensor.sample_ray(0.0, 0.5, mi.Point2f(sx, sy), mi.Point2f(0.5, 0.5))
        lines.append(f"ray {i} {sx!r} {sy!r} {ray.o[0]!r} {ray.o[1]!r} {ray.o[2]!r} "
                     f"{ray.d[0]!r} {ray.d[1]!r} {ray.d[2]!r}")
with open(os.path.join(here, "mitsuba_camera.txt"), "w") as f:
    f.write("\n".join(lines) + "\n")
print("wrote", len(lines), "lines")
