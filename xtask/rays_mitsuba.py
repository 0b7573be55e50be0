#!/usr/bin/env python3
"""Embree's side of `cargo xtask rays`: traces the rays trilux traced, on the
same triangles, with Mitsuba 3's `llvm_ad_rgb` variant (Embree inside).

    python3 xtask/rays_mitsuba.py RAYS.bin THREADS...

RAYS.bin (little-endian, written by xtask/src/rays.rs): b"TLXRAYS1", u32
scene count, then per scene: u32 name length, name (UTF-8), u32 triangle
count n, n*9 f32 (three vertices), u32 ray count, rays*6 f32 (origin, unit
direction; t up to infinity), u32 segment count, segments*6 f32 (the two
ends).

For each scene and thread count, prints one JSON object a line: scene,
threads, closest and shadow seconds (best of REPS runs, after one
untimed run that compiles and caches the LLVM kernel), hits (closest rays
that hit) and occluded (segments blocked). Closest hits are
`ray_intersect_preliminary` (the traversal alone, no surface interaction);
shadow rays are `ray_test` over each segment shortened by 1e-4 of its length
at both ends (Mitsuba's f32 rays would otherwise re-hit the surfaces the
ends lie on). Ray construction and upload are not timed.
"""
import json
import struct
import sys
import time

import numpy as np
import drjit as dr
import mitsuba as mi

REPS = 3


def read_scenes(path):
    data = open(path, "rb").read()
    if data[:8] != b"TLXRAYS1":
        raise SystemExit(f"{path}: not a rays file")
    off = 8

    def u32():
        nonlocal off
        (v,) = struct.unpack_from("<I", data, off)
        off += 4
        return v

    def floats(count, width):
        nonlocal off
        # Copied: the file's offsets are not 4-byte aligned, Embree's
        # buffers must be.
        a = np.frombuffer(data, "<f4", count * width, off).reshape(count, width).copy()
        off += 4 * count * width
        return a

    scenes = []
    for _ in range(u32()):
        n = u32()
        name = data[off:off + n].decode()
        off += n
        tris = floats(u32(), 9)
        rays = floats(u32(), 6)
        segs = floats(u32(), 6)
        scenes.append((name, tris, rays, segs))
    return scenes


def mesh_scene(tris):
    n = len(tris)
    mesh = mi.Mesh("triangles", 3 * n, n)
    params = mi.traverse(mesh)
    params["vertex_positions"] = mi.Float(np.ascontiguousarray(tris.reshape(-1)))
    params["faces"] = mi.UInt32(np.arange(3 * n, dtype=np.uint32))
    params.update()
    return mi.load_dict({"type": "scene", "mesh": mesh})


def vec(a, cls):
    return cls(*(np.ascontiguousarray(a[:, i]) for i in range(3)))


def best_time(f):
    """Best wall time of REPS runs of f after an untimed one, and f's last
    result."""
    result = f()
    best = float("inf")
    for _ in range(REPS):
        t0 = time.perf_counter()
        result = f()
        best = min(best, time.perf_counter() - t0)
    return best, result


def main():
    path, threads = sys.argv[1], [int(t) for t in sys.argv[2:]]
    mi.set_variant("llvm_ad_rgb")
    mi.set_log_level(mi.LogLevel.Error)
    for name, tris, rays, segs in read_scenes(path):
        scene = mesh_scene(tris)
        ray = mi.Ray3f(vec(rays[:, :3], mi.Point3f), vec(rays[:, 3:], mi.Vector3f))
        p, q = segs[:, :3].astype(np.float64), segs[:, 3:].astype(np.float64)
        d = q - p
        length = np.linalg.norm(d, axis=1)
        length[length == 0.0] = 1.0
        dn = d / length[:, None]
        eps = 1e-4 * length
        shadow = mi.Ray3f(
            vec((p + dn * eps[:, None]).astype(np.float32), mi.Point3f),
            vec(dn.astype(np.float32), mi.Vector3f),
        )
        shadow.maxt = mi.Float((length - 2.0 * eps).astype(np.float32))
        dr.eval(ray, shadow)
        for t in threads:
            dr.set_thread_count(t)

            def closest():
                pi = scene.ray_intersect_preliminary(ray)
                dr.eval(pi.t, pi.prim_index)
                dr.sync_thread()
                return pi

            def occluded():
                hit = scene.ray_test(shadow)
                dr.eval(hit)
                dr.sync_thread()
                return hit

            tc, pi = best_time(closest)
            ts, hit = best_time(occluded)
            out = {
                "scene": name,
                "threads": t,
                "closest": tc,
                "shadow": ts,
                "hits": int(dr.count(pi.is_valid())[0]),
                "occluded": int(dr.count(hit)[0]),
            }
            print(json.dumps(out), flush=True)


if __name__ == "__main__":
    main()
