"""scripts/mitsuba06_to_3.py: a Mitsuba 0.6 file upgraded loads unchanged in
Mitsuba 3 and in trilux, with the same shapes and the same emitted power
(Mitsuba's areas against trilux's); a `serialized` mesh written here by the
documented layout reads the same in both. Run from .ci/run with the release
`trilux` (TRILUX_BIN names another binary).
"""
import json
import math
import os
import pathlib
import struct
import subprocess
import sys
import zlib

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "scripts" / "mitsuba06_to_3.py"
BIN = pathlib.Path(os.environ.get("TRILUX_BIN", ROOT / "target" / "release" / "trilux"))

# Mitsuba 0.6 constructs that occur in Bitterli's scenes (dppm-scenes) and
# some more, in the part of Mitsuba that trilux reads.
SCENE_06 = """<?xml version="1.0" encoding="utf-8"?>
<scene version="0.6.0">
  <default name="method" value="sppm"/>
  <integrator type="$method">
    <integer name="maxDepth" value="65"/>
    <integer name="photonCount" value="100000"/>
  </integrator>
  <sensor type="perspective">
    <float name="fov" value="40"/>
    <string name="fovAxis" value="x"/>
    <transform name="toWorld">
      <lookAt origin="0, 1, 6" target="0, 1, 0" up="0, 1, 0"/>
    </transform>
    <sampler type="halton"><integer name="sampleCount" value="16"/></sampler>
    <film type="ldrfilm">
      <integer name="width" value="32"/><integer name="height" value="24"/>
      <float name="gamma" value="2.2"/><boolean name="banner" value="false"/>
      <rfilter type="box"/>
    </film>
  </sensor>
  <bsdf type="twosided" id="Rough">
    <bsdf type="roughdiffuse">
      <srgb name="diffuseReflectance" value="#808080"/>
      <float name="alpha" value="0.3"/>
    </bsdf>
  </bsdf>
  <bsdf type="twosided" id="Brass">
    <bsdf type="roughconductor">
      <float name="alpha" value="0.1"/>
      <string name="distribution" value="ggx"/>
      <float name="extEta" value="1"/>
      <rgb name="specularReflectance" value="1, 1, 1"/>
      <rgb name="eta" value="2.8656, 2.11918, 1.94008"/>
      <rgb name="k" value="3.03233, 2.05611, 1.61629"/>
    </bsdf>
  </bsdf>
  <bsdf type="diffuse" id="Checked">
    <texture name="diffuseReflectance" type="checkerboard">
      <float name="uscale" value="4"/><float name="vscale" value="2"/>
      <float name="uoffset" value="0.25"/>
    </texture>
  </bsdf>
  <shape type="rectangle">
    <transform name="toWorld"><scale x="3" y="2"/><rotate x="1" angle="-90"/></transform>
    <ref id="Checked"/>
  </shape>
  <shape type="serialized">
    <string name="filename" value="meshes.serialized"/>
    <integer name="shapeIndex" value="1"/>
    <boolean name="faceNormals" value="true"/>
    <transform name="toWorld"><scale value="0.5"/><translate y="1"/></transform>
    <ref id="Brass"/>
  </shape>
  <shape type="obj">
    <string name="filename" value="tri.obj"/>
    <float name="maxSmoothAngle" value="30"/>
    <ref id="Rough"/>
    <emitter type="area"><rgb name="radiance" value="2, 2, 2"/></emitter>
  </shape>
  <shape type="serialized">
    <string name="filename" value="meshes.serialized"/>
    <transform name="toWorld"><translate y="2"/></transform>
    <emitter type="area"><rgb name="radiance" value="3, 3, 3"/></emitter>
  </shape>
</scene>
"""


def serialized_mesh(positions, triangles, version=4):
    """One mesh of a serialized file, by Mitsuba's documented layout
    (single precision, no normals)."""
    body = struct.pack("<I", 0x1000)
    if version == 4:
        body += b"mesh\0"
    body += struct.pack("<QQ", len(positions), len(triangles))
    body += b"".join(struct.pack("<3f", *p) for p in positions)
    body += b"".join(struct.pack("<3I", *t) for t in triangles)
    return struct.pack("<HH", 0x041C, version) + zlib.compress(body)


def serialized_file(meshes, version=4):
    out, offsets = b"", []
    for m in meshes:
        offsets.append(len(out))
        out += m
    out += b"".join(struct.pack("<Q" if version == 4 else "<I", o) for o in offsets)
    return out + struct.pack("<I", len(meshes))


def upgrade(src, dst):
    return subprocess.run([sys.executable, str(SCRIPT), str(src), "-o", str(dst)],
                          capture_output=True, text=True)


def write_scene(tmp_path):
    tri = serialized_mesh([(0, 0, 0), (1, 0, 0), (0, 1, 0)], [(0, 1, 2)])
    # Mesh 1: a unit square.
    square = serialized_mesh([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)], [(0, 1, 2), (0, 2, 3)])
    (tmp_path / "meshes.serialized").write_bytes(serialized_file([tri, square]))
    (tmp_path / "tri.obj").write_text("v -1 0.5 -1\nv 1 0.5 -1\nv 0 2 -1\nf 1 2 3\n")
    src = tmp_path / "scene06.xml"
    src.write_text(SCENE_06)
    return src


def test_an_upgraded_file_loads_the_same_in_mitsuba_3_and_trilux(tmp_path):
    mi = pytest.importorskip("mitsuba")
    mi.set_variant("scalar_rgb")
    src = write_scene(tmp_path)
    dst = tmp_path / "scene3.xml"
    run = upgrade(src, dst)
    assert run.returncode == 0, run.stderr
    log = run.stderr
    for change in ["scene version 0.6.0 -> 3.0.0", "parameter toWorld -> to_world",
                   "<lookAt> -> <lookat>", 'type "diffuse"', 'type "hdrfilm"',
                   'type "independent"', 'type "path"', "to_uv", "ext_eta dropped",
                   "face_normals true", "(linearised)"]:
        assert change in log, f"{change!r} not in {log}"
    scene = mi.load_file(str(dst))
    # Emitted power of a Lambertian emitter: pi * area * radiance (seen
    # along the normal).
    si = mi.SurfaceInteraction3f()
    si.wi = mi.Vector3f(0, 0, 1)
    power = sum(math.pi * s.surface_area() * s.emitter().eval(si, True)[0]
                for s in scene.shapes() if s.emitter())
    out = subprocess.run([str(BIN), "info", "--json", str(dst)], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    info = json.loads(out.stdout)
    assert info["shapes"] == len(scene.shapes()) == 4
    assert info["bsdfs"].get("roughconductor") == 1 and "roughdiffuse" not in info["bsdfs"]
    assert abs(info["emitted_power"][0] / power - 1) < 1e-6, (info, power)
    # The obj triangle (area 1.5, radiance 2) and mesh 0 of the serialized
    # file, its triangle raised by 2 (area 0.5, radiance 3): 3 pi + 1.5 pi.
    assert abs(power / (4.5 * math.pi) - 1) < 1e-6, power


def test_phong_and_ward_become_roughplastic_with_matching_roughness(tmp_path):
    mi = pytest.importorskip("mitsuba")
    mi.set_variant("scalar_rgb")
    src = tmp_path / "glossy06.xml"
    src.write_text("""<scene version="0.6.0">
  <bsdf type="phong" id="p"><float name="exponent" value="48"/>
    <rgb name="diffuseReflectance" value="0.2, 0.3, 0.4"/></bsdf>
  <bsdf type="ward" id="w"><float name="alphaU" value="0.04"/><float name="alphaV" value="0.25"/></bsdf>
  <bsdf type="coating" id="c"><float name="intIOR" value="1.5"/><bsdf type="diffuse"/></bsdf>
  <bsdf type="mixturebsdf" id="m"><string name="weights" value="0.25, 0.75"/>
    <bsdf type="diffuse"/><ref id="c"/></bsdf>
  <shape type="sphere"><ref id="p"/></shape>
  <shape type="sphere"><ref id="w"/></shape>
  <shape type="sphere"><ref id="m"/></shape>
</scene>
""")
    dst = tmp_path / "glossy3.xml"
    run = upgrade(src, dst)
    assert run.returncode == 0, run.stderr
    scene = mi.load_file(str(dst))
    params = mi.traverse(scene)
    alphas = sorted(v for k, v in params.items() if k.endswith(".alpha"))
    # Phong exponent 48: sqrt(2 / 50) = 0.2; Ward: sqrt(0.04 * 0.25) = 0.1.
    assert alphas == pytest.approx([0.1, 0.2], abs=1e-6), alphas
    weights = [v for k, v in params.items() if k.endswith("weight.value")]
    assert weights == pytest.approx([0.75]), weights


def test_a_plugin_without_equivalent_is_listed_and_fails(tmp_path):
    src = tmp_path / "irawan.xml"
    src.write_text('<scene version="0.6.0"><bsdf type="irawan" id="cloth"/></scene>')
    run = upgrade(src, tmp_path / "out.xml")
    assert run.returncode == 1
    assert 'left as is: <bsdf type="irawan" id="cloth">' in run.stderr
    bad = tmp_path / "bad.xml"
    bad.write_text("<scene version='0.6.0'><shape></scene>")
    run = upgrade(bad, tmp_path / "out.xml")
    assert run.returncode == 1 and run.stderr.startswith(f"error: {bad}:"), run.stderr


SKY_06 = """<scene version="0.6.0">
  <emitter type="sunsky">
    <float name="turbidity" value="3"/>
    <vector name="sunDirection" x="-0.5" y="0.6" z="0.3"/>
    <float name="skyScale" value="2"/>
    <float name="sunScale" value="1"/>
    <integer name="resolution" value="256"/>
  </emitter>
  <shape type="rectangle">
    <transform name="toWorld"><rotate x="1" angle="-90"/></transform>
    <bsdf type="diffuse"/>
  </shape>
</scene>
"""



def brute_irradiance(mi, np, emitter, sun, cone=math.radians(1.0), n=4_000_000):
    """E = ∫ L cos θ dω over the upper hemisphere (y up) of Mitsuba 3's own
    `emitter.eval`, by Monte Carlo independent of any pixel grid: the sky
    outside a 1° cone around the sun by cosine-weighted directions, the cone
    (the sun's disc is 0.27° in radius) by uniform directions in it."""
    rng = np.random.default_rng(7)

    def radiance(x, y, z):
        si = mi.SurfaceInteraction3f()
        si.wi = mi.Vector3f(-x, -y, -z)
        return np.array(emitter.eval(si))

    u1, u2 = rng.random(n), rng.random(n)
    r, phi = np.sqrt(u1), 2 * np.pi * u2
    x, z, y = r * np.cos(phi), r * np.sin(phi), np.sqrt(1 - u1)
    outside = x * sun[0] + y * sun[1] + z * sun[2] < math.cos(cone)
    sky = math.pi * (radiance(x, y, z) * outside).mean(axis=1)
    # Uniform in the cone: cos α uniform in [cos cone, 1], about the sun.
    c = 1 - rng.random(n) * (1 - math.cos(cone))
    s_, phi = np.sqrt(1 - c * c), 2 * np.pi * rng.random(n)
    t1 = np.cross(sun, [0.0, 0.0, 1.0] if abs(sun[2]) < 0.9 else [1.0, 0.0, 0.0])
    t1 /= np.linalg.norm(t1)
    t2 = np.cross(sun, t1)
    d = (np.outer(sun, c) + np.outer(t1, s_ * np.cos(phi)) + np.outer(t2, s_ * np.sin(phi)))
    solid = 2 * math.pi * (1 - math.cos(cone))
    disc = solid * (radiance(*d) * np.maximum(d[1], 0)).mean(axis=1)
    return sky + disc


def test_a_sunsky_becomes_the_envmap_it_rasterises_to(tmp_path):
    """0.6 drew its sunsky into an envmap; the upgrade does the same with
    Mitsuba 3's sunsky. The map must carry the sky's and the sun's light:
    the irradiance it gives an upward plane equals the brute-force integral
    of Mitsuba 3's sunsky within 1 % (the brute force's own standard error
    is under 0.2 % at 4 million directions for each part; the map's
    pixels are solid-angle means of 8 × 8, around the sun 64 × 64, samples),
    and trilux loads the upgraded file."""
    pytest.importorskip("mitsuba")
    np = pytest.importorskip("numpy")
    sys.path.insert(0, str(ROOT / "scripts"))
    import sunsky_envmap
    src = tmp_path / "sky06.xml"
    src.write_text(SKY_06)
    raster, keep = tmp_path / "sky3.xml", tmp_path / "keep3.xml"
    run = upgrade(src, raster)
    assert run.returncode == 0, run.stderr
    assert '-> type "envmap" sky3-sky.exr, 256 x 128' in run.stderr, run.stderr
    run = subprocess.run([sys.executable, str(SCRIPT), str(src), "-o", str(keep),
                          "--sunsky", "keep"], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    mi = sunsky_envmap.load_mitsuba()
    image = np.array(mi.Bitmap(str(tmp_path / "sky3-sky.exr")), dtype=float)
    height, width, _ = image.shape
    e_map = sunsky_envmap.irradiance(np, image.reshape(-1, 3).T, width, height)
    sun = np.array([-0.5, 0.6, 0.3]) / math.sqrt(0.7)
    e_sky = brute_irradiance(mi, np, mi.load_file(str(keep)).emitters()[0], sun)
    print("irradiance under the map", e_map, "brute force of the sunsky", e_sky)
    for m, s in zip(e_map, e_sky):
        assert abs(m / s - 1) < 0.01, (e_map, e_sky)
    out = subprocess.run([str(BIN), "info", str(raster)], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
