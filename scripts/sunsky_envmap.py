"""A Mitsuba 3 `sunsky` emitter rasterised into an `envmap` image.

Mitsuba 0.6 drew its `sunsky` into an environment map of `resolution` × 
`resolution`/2 pixels and lit the scene with that map; trilux reads
`envmap` but not Mitsuba 3's analytic `sunsky`. `mitsuba06_to_3.py` uses this
module to do what 0.6 did: evaluate Mitsuba 3's own `sunsky` (the upgraded
element, with its `to_world`) over the sphere and write the equirectangular
image that Mitsuba 3's `envmap` (and trilux's) reads back in world
directions, so the two renderers light the upgraded file with the same sky.

Each pixel holds the mean radiance over its solid angle (sub-pixel samples
weighted by sin θ), so the map carries the sky's and the sun's power, not
point values: the sun's disc (0.54° wide by default, about one pixel at 512)
is sampled 64 × 64 per pixel around its brightest pixel, 8 × 8 elsewhere.

The pixel (column u, row v) of a W × H map looks along, in Mitsuba 3's
`envmap` convention (`src/emitters/envmap.cpp`: u = atan2(x, −z) / 2π,
v = acos(y) / π):
    d = (sin θ sin φ, cos θ, −sin θ cos φ),  φ = 2π u,  θ = π v.

Needs Mitsuba 3 with an LLVM variant (`llvm_ad_rgb`; Debian's libLLVM 19, and
`DRJIT_LIBLLVM_PATH` if drjit does not find it).
"""
import glob
import math
import os

BASE_SUBSAMPLES = 8
SUN_SUBSAMPLES = 64
SUN_WINDOW = 2  # pixels on each side of the brightest one


def find_libllvm():
    """Points drjit at the distribution's libLLVM when it is not told where
    one is (Debian's libllvm19 installs it outside drjit's search path)."""
    if os.environ.get("DRJIT_LIBLLVM_PATH"):
        return
    found = sorted(glob.glob("/usr/lib/*/libLLVM.so.*") + glob.glob("/usr/lib/*/libLLVM-*.so"))
    if found:
        os.environ["DRJIT_LIBLLVM_PATH"] = found[-1]


def load_mitsuba():
    """Mitsuba 3 in a vectorised variant, or an error saying what is missing."""
    find_libllvm()
    try:
        import mitsuba as mi
    except ImportError as e:
        raise RuntimeError("rasterising a sunsky needs Mitsuba 3 (pip install mitsuba)") from e
    for variant in ("llvm_ad_rgb", "llvm_rgb"):
        try:
            mi.set_variant(variant)
            return mi
        except (ImportError, AttributeError, RuntimeError):
            continue
    raise RuntimeError("rasterising a sunsky needs Mitsuba 3's llvm_ad_rgb variant "
                       "(libLLVM; set DRJIT_LIBLLVM_PATH)")


def directions(np, u, v):
    """World directions of the map coordinates (u, v) ∈ [0, 1)²."""
    phi, theta = 2 * math.pi * u, math.pi * v
    st = np.sin(theta)
    return st * np.sin(phi), np.cos(theta), -st * np.cos(phi)


def pixel_means(mi, np, emitter, cols, rows, width, height, n):
    """Mean radiance (RGB) over the solid angle of each pixel (cols[i],
    rows[i]), from n × n sub-pixel samples weighted by sin θ."""
    k = (np.arange(n) + 0.5) / n
    su, sv = np.meshgrid(k, k, indexing="xy")
    u = (cols[:, None] + su.ravel()[None, :]) / width
    v = (rows[:, None] + sv.ravel()[None, :]) / height
    x, y, z = directions(np, u.ravel(), v.ravel())
    si = mi.SurfaceInteraction3f()
    si.wi = mi.Vector3f(-x, -y, -z)
    radiance = np.array(emitter.eval(si)).reshape(3, len(cols), n * n)
    w = np.sin(math.pi * v)
    return (radiance * w[None]).sum(axis=2) / w.sum(axis=1)[None]


def rasterise(emitter_xml, path, width=512):
    """Writes the `sunsky` element `emitter_xml` (Mitsuba 3 XML) as an
    equirectangular EXR of width × width/2 pixels at `path`; returns the
    map's total power per unit area on an upward plane (its irradiance, W/m²
    per channel) for the record."""
    mi = load_mitsuba()
    import numpy as np
    scene = mi.load_string(f'<scene version="3.0.0">{emitter_xml}</scene>')
    emitter = scene.emitters()[0]
    height = width // 2
    rows, cols = np.divmod(np.arange(width * height), width)
    image = np.empty((3, height * width))
    for s in range(0, len(rows), 8192):
        sl = slice(s, s + 8192)
        image[:, sl] = pixel_means(mi, np, emitter, cols[sl], rows[sl], width, height,
                                   BASE_SUBSAMPLES)
    refine_sun(mi, np, emitter, image, width, height)
    rgb = image.T.reshape(height, width, 3).astype(np.float32)
    mi.Bitmap(rgb, pixel_format=mi.Bitmap.PixelFormat.RGB).write(str(path))
    return irradiance(np, image, width, height)


def refine_sun(mi, np, emitter, image, width, height):
    """Resamples the window around the brightest pixel (the sun) finely."""
    brightest = int(np.argmax(image.sum(axis=0)))
    r0, c0 = divmod(brightest, width)
    win = range(-SUN_WINDOW, SUN_WINDOW + 1)
    pix = [((r0 + dr) , (c0 + dc) % width) for dr in win for dc in win if 0 <= r0 + dr < height]
    rows = np.array([p[0] for p in pix], dtype=float)
    cols = np.array([p[1] for p in pix], dtype=float)
    means = pixel_means(mi, np, emitter, cols, rows, width, height, SUN_SUBSAMPLES)
    for i, (r, c) in enumerate(pix):
        image[:, r * width + c] = means[:, i]


def irradiance(np, image, width, height):
    """E = Σ L cos θ dω over the upper hemisphere (y up), per channel."""
    v = (np.arange(height) + 0.5) / height
    theta = math.pi * v
    d_omega = (2 * math.pi / width) * (math.pi / height) * np.sin(theta)
    weight = np.repeat(np.maximum(np.cos(theta), 0) * d_omega, width)
    return [float(c) for c in (image * weight[None]).sum(axis=1)]
