#!/usr/bin/env python3
"""Times Mitsuba 3's path tracer on one scene for `cargo xtask sweep`.

    python3 tests/golden/mitsuba_time.py SCENE.xml|.gltf|.glb RES SPP OUT.exr [SEED]

Renders SCENE at RES x RES with SPP samples per pixel (path, max_depth -1,
the same preparation as make_references.py: film size and integrator
replaced), writes OUT.exr (linear sRGB float32) and prints one line
`seconds S` with the wall time of the render alone: the scene is loaded and
a 1-spp render run first so that LLVM's kernel compilation is not counted
(Mitsuba caches compiled kernels; the first run of a session pays it once).
"""
import os
import sys
import time

import numpy as np
import mitsuba as mi

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import make_references as mr  # noqa: E402

scene_path, res, spp, out = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
seed = int(sys.argv[5]) if len(sys.argv) > 5 else 1000
if os.path.splitext(scene_path)[1] in (".gltf", ".glb"):
    # As make_references.py does: the converter writes the XML Mitsuba reads.
    import tempfile
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "../../scripts"))
    import gltf_to_mitsuba  # noqa: E402
    mi.set_variant("scalar_rgb")
    scene_path = gltf_to_mitsuba.convert(scene_path, tempfile.mkdtemp(prefix="trilux-sweep-"))
mi.set_variant("llvm_ad_spectral" if mr.is_spectral(scene_path) else "llvm_ad_rgb")
scene = mr.load(scene_path, res, -1)
mi.render(scene, spp=1, seed=seed + 1)
t0 = time.time()
img = np.array(mi.render(scene, spp=spp, seed=seed))[:, :, :3]
seconds = time.time() - t0
mr.write_exr(out, img)
print(f"seconds {seconds:.6f}")
