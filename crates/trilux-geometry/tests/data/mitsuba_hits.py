#!/usr/bin/env python3
"""Reference ray hits from Mitsuba 3 (scalar_rgb) for trilux-geometry's
convention test (tests/mitsuba.rs).

Writes mitsuba_hits.csv: `shape` lines (kind, flip_normals, the 4x4
to_world matrix row by row, then kind parameters) and `ray` lines (shape
index, origin, direction, hit or not, t, geometric normal). Rays whose
outcome changes under a 1e-3 jitter of the origin (silhouettes, edges) are
left out: Mitsuba traces in float32, trilux in float64.

Run: python3 crates/trilux-geometry/tests/data/mitsuba_hits.py
"""
import math
import os
import random
import tempfile

import mitsuba as mi

mi.set_variant("scalar_rgb")
T = mi.ScalarTransform4f


def mat(t):
    m = t.matrix
    return [float(m[i][j]) for i in range(4) for j in range(4)]


MESH = {
    "v": [[x * 0.5 - 0.5, y * 0.5 - 0.5, 0.3 * math.sin(1.5 * x) * (y - 1.0)] for y in range(3) for x in range(3)],
    "f": [[0, 1, 4], [0, 4, 3], [1, 2, 5], [1, 5, 4], [3, 4, 7], [3, 7, 6], [4, 5, 8], [4, 8, 7]],
}

SHAPES = [
    ("rectangle", False, T().translate([0.3, -0.2, 0.5]) @ T().rotate([1, 2, 0.5], 37) @ T().scale([1.5, 0.7, 1.0]), {}),
    ("rectangle", True, T().translate([0.0, 0.0, -0.4]) @ T().rotate([0, 1, 0], 120), {}),
    ("cube", False, T().translate([0.1, 0.2, -0.3]) @ T().rotate([0.3, 1, 0.2], 25) @ T().scale([1.2, 0.6, 0.9]), {}),
    ("cube", True, T().scale([2.0, 1.5, 1.0]), {}),
    ("disk", False, T().translate([0.5, 0.5, 0.0]) @ T().rotate([1, 0, 0], 70) @ T().scale([1.3, 0.8, 1.0]), {}),
    ("sphere", False, T().translate([0.2, 0.0, 0.1]) @ T().rotate([0, 0, 1], 30) @ T().scale(1.4), {"center": [0.1, -0.2, 0.3], "radius": 0.6}),
    ("sphere", True, T(), {"center": [0.0, 0.5, 0.0], "radius": 1.1}),
    # Mitsuba 3.9 composes `to_world` with p0/p1/radius into a sheared matrix
    # (it warns "'to_world' transform shouldn't contain any shearing" and a
    # radius of 0.45 under a rotation became 0.545), so each cylinder here
    # uses either p0/p1/radius or to_world, not both.
    ("cylinder", False, T(), {"p0": [0.1, 0.0, -0.5], "p1": [-0.2, 0.3, 0.9], "radius": 0.45}),
    ("cylinder", True, T().translate([0.2, -0.1, 0.3]) @ T().rotate([0, 1, 0], 90) @ T().scale(0.8), {"p0": [0.0, 0.0, 0.0], "p1": [0.0, 0.0, 1.0], "radius": 1.0}),
    # An OBJ mesh (a bent sheet of 8 triangles) with a mirroring transform:
    # Mitsuba computes face normals from the world-space winding.
    ("obj", False, T().translate([0.1, 0.0, 0.2]) @ T().scale([-1.0, 1.2, 0.9]) @ T().rotate([1, 0, 1], 20), MESH),
    ("obj", True, T().rotate([0, 1, 0], 35), MESH),
]


def load(kind, flip, to_world, params):
    d = {"type": kind, "flip_normals": flip}
    if kind == "obj":
        path = os.path.join(tempfile.mkdtemp(), "mesh.obj")
        with open(path, "w") as f:
            for v in params["v"]:
                f.write("v %r %r %r\n" % tuple(v))
            for t in params["f"]:
                f.write("f %d %d %d\n" % (t[0] + 1, t[1] + 1, t[2] + 1))
        d["filename"] = path
        d["face_normals"] = True
    if kind in ("sphere",):
        d["center"] = params["center"]
        d["radius"] = params["radius"]
        d["to_world"] = to_world
    elif kind == "cylinder":
        d["p0"] = params["p0"]
        d["p1"] = params["p1"]
        d["radius"] = params["radius"]
        d["to_world"] = to_world
    else:
        d["to_world"] = to_world
    return mi.load_dict({"type": "scene", "shape": d})


def trace(shape, o, d):
    si = shape.ray_intersect(mi.Ray3f(o, d))
    if not si.is_valid():
        return None
    return float(si.t), [float(si.n[0]), float(si.n[1]), float(si.n[2])]


def main():
    rng = random.Random(7)
    out = []
    for k, (kind, flip, tw, params) in enumerate(SHAPES):
        extra = []
        if kind == "sphere":
            extra = params["center"] + [params["radius"]]
        if kind == "cylinder":
            extra = params["p0"] + params["p1"] + [params["radius"]]
        if kind == "obj":
            extra = [len(params["v"])] + [c for v in params["v"] for c in v] + [len(params["f"])] + [i for t in params["f"] for i in t]
        out.append(",".join(["shape", kind, str(int(flip))] + [repr(x) for x in mat(tw)] + [repr(float(x)) for x in extra]))
        shape = load(kind, flip, tw, params)
        bb = shape.bbox()
        lo = [float(bb.min[i]) for i in range(3)]
        hi = [float(bb.max[i]) for i in range(3)]
        kept = 0
        while kept < 150:
            target = [rng.uniform(lo[i] - 0.2, hi[i] + 0.2) for i in range(3)]
            if rng.random() < 0.3:
                # Some rays start inside the bounding box (inside closed shapes).
                o = [rng.uniform(lo[i], hi[i]) for i in range(3)]
            else:
                dirn = [rng.gauss(0, 1) for _ in range(3)]
                n = math.sqrt(sum(x * x for x in dirn))
                o = [target[i] + 4.0 * dirn[i] / n for i in range(3)]
            d = [target[i] - o[i] for i in range(3)]
            if math.sqrt(sum(x * x for x in d)) < 1e-3:
                continue
            h = trace(shape, o, d)
            stable = True
            for j in range(6):
                oj = list(o)
                oj[j // 2] += 1e-3 if j % 2 == 0 else -1e-3
                hj = trace(shape, oj, d)
                if (hj is None) != (h is None) or (h is not None and abs(hj[0] - h[0]) > 0.05 * (1 + h[0])):
                    stable = False
            if not stable:
                continue
            if h is None:
                out.append(",".join(["ray", str(k)] + [repr(x) for x in o + d] + ["0", "0", "0", "0", "0"]))
            else:
                out.append(",".join(["ray", str(k)] + [repr(x) for x in o + d] + ["1", repr(h[0])] + [repr(x) for x in h[1]]))
            kept += 1
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "mitsuba_hits.csv")
    with open(path, "w") as f:
        f.write("# made by mitsuba_hits.py with Mitsuba " + mi.__version__ + " (scalar_rgb)\n")
        f.write("\n".join(out) + "\n")


if __name__ == "__main__":
    main()
