"""Mitsuba 3 references rendered in passes: what the make_references.py
scripts beside the test scenes share.

A reference is the average of `passes` renders of spp / passes samples
each, with seeds 0 .. passes - 1, so that the spread of the passes' image
means gives the standard error of the reference's own mean. It is written
as NAME.exr (the averaged image) and NAME.json (the mean per channel and
its relative standard error), which trilux's tests compare against.
"""
import json
import os
import re
import tempfile

import numpy as np
import mitsuba as mi


def render_passes(scene, spp, passes):
    """The `passes` renders of `scene`, as an array (passes, height,
    width, 3) of float64."""
    images = []
    for k in range(passes):
        img = mi.render(scene, spp=spp // passes, seed=k)
        images.append(np.array(img, dtype=np.float64)[..., :3])
    return np.array(images)


def mean_and_stderr(images):
    """The image mean per channel over all passes, and its standard error
    from the spread of the passes' means, relative to the mean."""
    passes = len(images)
    means = images.reshape(passes, -1, 3).mean(axis=1)
    mean = means.mean(axis=0)
    stderr = means.std(axis=0, ddof=1) / np.sqrt(passes) / np.abs(mean)
    return mean, stderr


def write_reference(folder, name, scene_file, images, spp, extra=None):
    """Writes NAME.exr and NAME.json into `folder` from the passes'
    `images` (render_passes), `extra` fields appended to the record;
    prints the record and returns it."""
    mean, stderr = mean_and_stderr(images)
    mi.Bitmap(images.mean(axis=0).astype(np.float32)).write(
        os.path.join(folder, name + ".exr")
    )
    rec = {
        "scene": scene_file,
        "mitsuba": mi.MI_VERSION,
        "variant": mi.variant(),
        "spp": spp,
        "passes": len(images),
        "mean_rgb": [round(float(x), 7) for x in mean],
        "mean_rel_stderr": [round(float(x), 6) for x in stderr],
    }
    rec.update(extra or {})
    with open(os.path.join(folder, name + ".json"), "w", encoding="utf-8") as f:
        json.dump(rec, f, indent=2)
        f.write("\n")
    print(json.dumps(rec), flush=True)
    return rec


def load_gltf(path, size=64):
    """A glTF scene converted for Mitsuba by gltf_to_mitsuba.py (beside
    this file), its film set to size x size, loaded."""
    import gltf_to_mitsuba  # noqa: E402

    out = tempfile.mkdtemp()
    xml = gltf_to_mitsuba.convert(path, out)
    text = open(xml, encoding="utf-8").read()
    text = re.sub(r'name="width" value="\d+"', f'name="width" value="{size}"', text)
    text = re.sub(r'name="height" value="\d+"', f'name="height" value="{size}"', text)
    with open(xml, "w", encoding="utf-8") as f:
        f.write(text)
    return mi.load_file(xml)
