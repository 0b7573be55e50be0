#!/usr/bin/env python3
"""The small equirectangular sky of tests/envmap/: sky.exr, 64 x 32 texels
of linear RGB in Mitsuba 3's envmap layout (u = column along phi, v = row
from the +y pole down), a blue-to-white gradient from the zenith to the
horizon, a dim brown ground below it and a bright sun-like blob
(a Gaussian 2 texels wide) at 35 degrees above the horizon; and
uniform.exr, 8 x 4 texels of one value (the constant sky's test); and
nan.exr, 4 x 2 texels one of which is not a number (a bad input test).

Usage: python3 tests/envmap/make_envmap.py   (writes beside this script)
"""
import os

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
W, H = 64, 32
SUN_THETA = np.radians(90 - 35)  # from the +y pole
SUN_U = 0.3  # along phi, as a share of the turn
SUN = np.array([400.0, 360.0, 300.0])


def sky():
    img = np.zeros((H, W, 3))
    for j in range(H):
        theta = (j + 0.5) / H * np.pi
        for i in range(W):
            if theta < np.pi / 2:
                t = theta / (np.pi / 2)  # 0 at the zenith, 1 at the horizon
                img[j, i] = (1 - t) * np.array([0.3, 0.5, 1.0]) + t * np.array([1.0, 1.0, 1.0])
            else:
                img[j, i] = [0.15, 0.1, 0.05]
            du = min(abs((i + 0.5) / W - SUN_U), 1 - abs((i + 0.5) / W - SUN_U)) * W
            dv = ((j + 0.5) / H - SUN_THETA / np.pi) * H
            img[j, i] += SUN * np.exp(-(du * du + dv * dv) / (2 * 1.0**2))
    return img


def main():
    import mitsuba as mi

    mi.set_variant("scalar_rgb")
    mi.Bitmap(sky().astype(np.float32)).write(os.path.join(HERE, "sky.exr"))
    mi.Bitmap(np.full((4, 8, 3), [1.0, 0.8, 0.6], dtype=np.float32)).write(
        os.path.join(HERE, "uniform.exr")
    )
    nan = np.ones((2, 4, 3), dtype=np.float32)
    nan[1, 2, 1] = np.nan
    mi.Bitmap(nan).write(os.path.join(HERE, "nan.exr"))


if __name__ == "__main__":
    main()
