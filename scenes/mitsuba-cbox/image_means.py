"""What the reference scripts beside it share: an image mean over passes
with its relative standard error, and the JSON they write."""
import json

import numpy as np


def mean_over_passes(mi, scene, spp, passes, integrator=None):
    """The per-channel image mean of `spp` samples per pixel rendered in
    `passes` passes with seeds 0..passes-1, and its relative standard error
    (the passes' spread / sqrt(passes) / |mean|)."""
    means = []
    for k in range(passes):
        img = mi.render(scene, integrator=integrator, spp=spp // passes, seed=k)
        means.append(np.array(img, dtype=np.float64).reshape(-1, 3).mean(axis=0))
    means = np.array(means)
    mean = means.mean(axis=0)
    stderr = means.std(axis=0, ddof=1) / np.sqrt(passes) / np.maximum(np.abs(mean), 1e-30)
    return mean, stderr


def rounded(mean, stderr):
    """The JSON of one case's mean and standard error."""
    return {
        "mean_rgb": [round(float(x), 7) for x in mean],
        "mean_rel_stderr": [round(float(x), 6) for x in stderr],
    }


def write(path, rec):
    """Writes `rec` as indented JSON with a final newline, and prints it."""
    with open(path, "w", encoding="utf-8") as f:
        json.dump(rec, f, indent=2)
        f.write("\n")
    print(json.dumps(rec))
