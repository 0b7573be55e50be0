#!/usr/bin/env python3
"""Expected values for trilux-scene's tests, computed by Mitsuba 3.

Run from this folder:  python3 mitsuba_expected.py > mitsuba_expected.json

Each case is an XML fragment; the test (tests/mitsuba.rs) wraps it the same
way, loads it with trilux-scene and compares with what Mitsuba 3 (variant
scalar_rgb, single precision) built from the same text:
- "transforms": the `to_world` of a rectangle with that <transform>;
- "sensors": the sensor's to_world matrix and its horizontal fov (x_fov);
- "areas": the surface area of a shape;
- "meshes": positions, vertex normals and texture coordinates of OBJ and
  PLY meshes (the PLY files are made by make_ply.py);
- "textures": the diffuse reflectance of a rectangle textured with a
  `bitmap` (ramp.png, 4 x 2 texels) or `checkerboard`, with `to_uv`
  transforms, at fixed texture coordinates;
- "rays": for each shape of "areas" (and flip_normals variants), rays aimed
  near the shape's bounding-box centre from fixed pseudo-random origins, with
  Mitsuba's hit distance and geometric normal (or a miss): the scene's object
  conventions as the geometry layer sees them.
"""
import json

import mitsuba as mi

mi.set_variant("scalar_rgb")
# Mitsuba logs to stdout; only errors (the PLY colour warning is expected).
mi.set_log_level(mi.LogLevel.Error)

HEAD = '<scene version="3.0.0">'


def matrix(t):
    m = t.matrix
    return [[float(m[i][j]) for j in range(4)] for i in range(4)]


TRANSFORMS = [
    '<translate x="1" y="-2" z="3"/>',
    '<translate value="1, -2, 3"/>',
    '<scale value="2"/>',
    '<scale value="2, 3, 4"/>',
    '<scale x="2" z="-1"/>',
    '<rotate x="1" angle="90"/>',
    '<rotate y="1" angle="-17"/>',
    '<rotate value="0.6, 0, 0.8" angle="33"/>',
    '<rotate x="0.48" y="0.6" z="0.64" angle="-120"/>',
    '<matrix value="1 2 3 4  0 1 0 -5  0 0 2 6  0 0 0 1"/>',
    '<lookat origin="1, 2, 3" target="0, 0, 0" up="0, 1, 0"/>',
    '<lookat origin="0, 0, 5" target="0, 0, 0"/>',
    '<lookat origin="1, -2, 0.5" target="3, 1, 1"/>',
    '<scale x="0.3" y="0.61" z="0.3"/><rotate y="1" angle="18.25"/><translate x="-0.33" y="-0.4" z="-0.28"/>',
    '<translate x="1"/><rotate z="1" angle="90"/><scale value="2"/>',
]

SENSORS = [
    '<float name="fov" value="45"/>',
    '<float name="fov" value="45"/><string name="fov_axis" value="x"/>',
    '<float name="fov" value="45"/><string name="fov_axis" value="y"/>',
    '<float name="fov" value="45"/><string name="fov_axis" value="smaller"/>',
    '<float name="fov" value="45"/><string name="fov_axis" value="larger"/>',
    '<float name="fov" value="45"/><string name="fov_axis" value="diagonal"/>',
    '<float name="fov" value="45"/><string name="fov_axis" value="smaller"/>'
    '<film type="hdrfilm"><integer name="width" value="300"/><integer name="height" value="400"/></film>',
    '<float name="fov" value="45"/><string name="fov_axis" value="larger"/>'
    '<film type="hdrfilm"><integer name="width" value="300"/><integer name="height" value="400"/></film>',
    '<float name="fov" value="45"/><string name="fov_axis" value="diagonal"/>'
    '<film type="hdrfilm"><integer name="width" value="300"/><integer name="height" value="400"/></film>',
    '<float name="fov" value="30"/><string name="fov_axis" value="y"/>'
    '<film type="hdrfilm"><integer name="width" value="300"/><integer name="height" value="400"/></film>',
    '',  # no fov: Mitsuba's 50 mm default
    '<transform name="to_world"><lookat origin="0, 0, 3.9" target="0, 0, 0" up="0, 1, 0"/></transform>',
    '<transform name="to_world"><lookat origin="1, 2, 3" target="0, 0.5, 0" up="0, 0, 1"/></transform>',
    '<transform name="to_world"><rotate y="1" angle="30"/><translate x="1" y="2" z="3"/></transform>',
    '<transform name="to_world"><scale x="-1"/><lookat origin="0, 1, 4" target="0, 0, 0" up="0, 1, 0"/></transform>',
]

AREAS = [
    '<shape type="rectangle"/>',
    '<shape type="rectangle"><transform name="to_world"><scale x="0.23" y="0.19" z="0.19"/>'
    '<rotate x="1" angle="90"/><translate y="0.99" z="0.01"/></transform></shape>',
    '<shape type="rectangle"><transform name="to_world"><matrix value="1 0.5 0 0  0 2 0 0  0 0 1 0  0 0 0 1"/></transform></shape>',
    '<shape type="cube"/>',
    '<shape type="cube"><transform name="to_world"><scale x="0.3" y="0.61" z="0.3"/><rotate y="1" angle="18.25"/></transform></shape>',
    '<shape type="disk"/>',
    '<shape type="disk"><transform name="to_world"><scale x="2" y="0.5"/><rotate x="1" angle="40"/></transform></shape>',
    '<shape type="sphere"/>',
    '<shape type="sphere"><float name="radius" value="0.25"/><point name="center" x="1" y="2" z="3"/></shape>',
    '<shape type="sphere"><float name="radius" value="0.5"/><transform name="to_world"><scale value="3"/><translate x="1"/></transform></shape>',
    '<shape type="cylinder"/>',
    '<shape type="cylinder"><point name="p0" value="0, 0, 0"/><point name="p1" value="1, 2, 2"/><float name="radius" value="0.3"/></shape>',
    '<shape type="cylinder"><float name="radius" value="0.5"/><transform name="to_world"><scale x="2" y="2" z="5"/></transform></shape>',
    '<shape type="obj"><string name="filename" value="quad.obj"/></shape>',
    '<shape type="obj"><string name="filename" value="pyramid.obj"/>'
    '<transform name="to_world"><scale x="2"/><rotate x="1" angle="10"/></transform></shape>',
    '<shape type="ply"><string name="filename" value="pyramid.ply"/></shape>',
    '<shape type="ply"><string name="filename" value="tent-le.ply"/>'
    '<transform name="to_world"><rotate y="1" angle="25"/><translate z="0.5"/></transform></shape>',
    '<shape type="ply"><string name="filename" value="tent-be.ply"/></shape>',
]

# Vertex normals Mitsuba computes for an OBJ or PLY without normals, or
# reads from a PLY with them, and the PLY's texture coordinates (matched by
# position).
MESHES = [
    '<shape type="obj"><string name="filename" value="pyramid.obj"/></shape>',
    '<shape type="ply"><string name="filename" value="pyramid.ply"/></shape>',
    '<shape type="ply"><string name="filename" value="tent-le.ply"/></shape>',
    '<shape type="ply"><string name="filename" value="tent-be.ply"/></shape>',
    '<shape type="obj"><string name="filename" value="uvquad.obj"/></shape>',
    '<shape type="obj"><string name="filename" value="uvquad.obj"/><boolean name="flip_tex_coords" value="false"/></shape>',
    '<shape type="ply"><string name="filename" value="tent-le.ply"/><boolean name="flip_tex_coords" value="true"/></shape>',
]


def load(xml):
    return mi.load_string(HEAD + xml + "</scene>")


out = {"mitsuba_version": mi.__version__, "transforms": [], "sensors": [], "areas": []}
for t in TRANSFORMS:
    scene = load(f'<shape type="rectangle"><transform name="to_world">{t}</transform></shape>')
    m = mi.traverse(scene.shapes()[0])["to_world"]
    out["transforms"].append({"xml": t, "matrix": matrix(m)})
for s in SENSORS:
    scene = load(f'<sensor type="perspective">{s}</sensor>')
    sensor = scene.sensors()[0]
    out["sensors"].append({
        "xml": s,
        "to_world": matrix(sensor.world_transform()),
        "x_fov": float(mi.traverse(sensor)["x_fov"]),
    })
for a in AREAS:
    scene = load(a)
    out["areas"].append({"xml": a, "area": float(scene.shapes()[0].surface_area())})
out["meshes"] = []
for m in MESHES:
    params = mi.traverse(load(m).shapes()[0])
    p = list(params["vertex_positions"])
    n = list(params["vertex_normals"])
    uv = list(params["vertex_texcoords"]) if "vertex_texcoords" in params else []
    out["meshes"].append({
        "xml": m,
        "positions": [p[i:i + 3] for i in range(0, len(p), 3)],
        "normals": [n[i:i + 3] for i in range(0, len(n), 3)],
        "texcoords": [uv[i:i + 2] for i in range(0, len(uv), 2)],
    })

TEXTURES = [
    '<texture type="bitmap" name="reflectance"><string name="filename" value="ramp.png"/>'
    '<boolean name="raw" value="true"/><string name="filter_type" value="nearest"/>'
    '<transform name="to_uv"><scale x="2" y="1"/></transform></texture>',
    '<texture type="bitmap" name="reflectance"><string name="filename" value="ramp.png"/>'
    '<boolean name="raw" value="true"/><string name="filter_type" value="nearest"/>'
    '<transform name="to_uv"><translate x="0.25" y="0.1"/></transform></texture>',
    '<texture type="bitmap" name="reflectance"><string name="filename" value="ramp.png"/>'
    '<boolean name="raw" value="true"/><string name="filter_type" value="nearest"/>'
    '<transform name="to_uv"><rotate z="1" angle="90"/></transform></texture>',
    '<texture type="bitmap" name="reflectance"><string name="filename" value="ramp.png"/>'
    '<string name="wrap_mode" value="mirror"/>'
    '<transform name="to_uv"><scale x="1.5" y="0.7"/><rotate z="1" angle="30"/><translate x="0.3"/></transform></texture>',
    '<texture type="checkerboard" name="reflectance"/>',
    '<texture type="checkerboard" name="reflectance"><rgb name="color0" value="0.9, 0.5, 0.1"/>'
    '<float name="color1" value="0.05"/><transform name="to_uv"><scale value="4"/></transform></texture>',
    '<texture type="checkerboard" name="reflectance"><float name="color0" value="0.1"/>'
    '<rgb name="color1" value="0.8, 0.6, 0.3"/></texture>',
]
TEXTURE_UVS = [(0.1, 0.1), (0.3, 0.15), (0.6, 0.2), (0.85, 0.35), (0.05, 0.8),
               (0.45, 0.6), (0.7, 0.9), (0.93, 0.55)]
out["textures"] = []
for t in TEXTURES:
    bsdf = load(f'<shape type="rectangle"><bsdf type="diffuse">{t}</bsdf></shape>').shapes()[0].bsdf()
    values = []
    for u, v in TEXTURE_UVS:
        si = mi.SurfaceInteraction3f()
        si.uv = mi.Point2f(u, v)
        si.wi = mi.Vector3f(0, 0, 1)
        r = bsdf.eval_diffuse_reflectance(si)
        values.append({"uv": [u, v], "rgb": [float(r[0]), float(r[1]), float(r[2])]})
    out["textures"].append({"xml": t, "values": values})


def lcg(seed):
    """A tiny deterministic generator (so the rays do not depend on numpy)."""
    state = seed
    while True:
        state = (state * 6364136223846793005 + 1442695040888963407) % 2**64
        yield (state >> 11) / 2**53


out["rays"] = []
RAY_SHAPES = [a for a in AREAS] + [
    '<shape type="sphere"><boolean name="flip_normals" value="true"/></shape>',
    '<shape type="cube"><boolean name="flip_normals" value="true"/></shape>',
    '<shape type="cylinder"><boolean name="flip_normals" value="true"/></shape>',
    '<shape type="disk"><boolean name="flip_normals" value="true"/>'
    '<transform name="to_world"><rotate x="1" angle="30"/></transform></shape>',
]
for k, xml in enumerate(RAY_SHAPES):
    scene = load(xml)
    bbox = scene.bbox()
    centre = (bbox.min + bbox.max) * 0.5
    extent = float(dr_max) if (dr_max := max(bbox.extents())) > 0 else 1.0
    rng = lcg(k + 1)
    rays = []
    for _ in range(24):
        # Origin on a sphere of radius 3 * extent around the centre.
        z = 2 * next(rng) - 1
        phi = 2 * 3.141592653589793 * next(rng)
        r = (1 - z * z) ** 0.5
        import math
        o = [centre[0] + 3 * extent * r * math.cos(phi),
             centre[1] + 3 * extent * r * math.sin(phi),
             centre[2] + 3 * extent * z]
        target = [centre[i] + 0.6 * extent * (next(rng) - 0.5) for i in range(3)]
        d = [target[i] - o[i] for i in range(3)]
        norm = math.sqrt(sum(x * x for x in d))
        d = [x / norm for x in d]
        si = scene.ray_intersect(mi.Ray3f(o, d))
        hit = bool(si.is_valid())
        rays.append({
            "origin": o,
            "dir": d,
            "t": float(si.t) if hit else None,
            "n": [float(si.n[i]) for i in range(3)] if hit else None,
        })
    out["rays"].append({"xml": xml, "rays": rays})
print(json.dumps(out, indent=1))
