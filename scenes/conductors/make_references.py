"""Mitsuba 3.9.1 references of the scenes beside this script (smooth and
named conductors: metal-box): NAME.exr (64 x 64, the pass-averaged
image) and NAME.json (the image mean per channel and its relative standard
error over 16 passes).

    python3 scenes/conductors/make_references.py [SPP]   # default 4096
"""
import json
import os
import sys

import numpy as np
import mitsuba as mi

mi.set_variant("llvm_ad_rgb")
HERE = os.path.dirname(os.path.abspath(__file__))
SCENES = ["metal-box"]


def main():
    spp = int(sys.argv[1]) if len(sys.argv) > 1 else 4096
    passes = 16
    names = sys.argv[2:] or SCENES
    for name in names:
        scene = mi.load_file(os.path.join(HERE, name + ".xml"))
        images = []
        for k in range(passes):
            img = mi.render(scene, spp=spp // passes, seed=k)
            images.append(np.array(img, dtype=np.float64)[..., :3])
        images = np.array(images)
        means = images.reshape(passes, -1, 3).mean(axis=1)
        mean = means.mean(axis=0)
        stderr = means.std(axis=0, ddof=1) / np.sqrt(passes) / np.abs(mean)
        mi.Bitmap(images.mean(axis=0).astype(np.float32)).write(
            os.path.join(HERE, name + ".exr")
        )
        rec = {
            "scene": name + ".xml",
            "mitsuba": mi.MI_VERSION,
            "variant": "llvm_ad_rgb",
            "spp": spp,
            "passes": passes,
            "mean_rgb": [round(float(x), 7) for x in mean],
            "mean_rel_stderr": [round(float(x), 6) for x in stderr],
        }
        with open(os.path.join(HERE, name + ".json"), "w", encoding="utf-8") as f:
            json.dump(rec, f, indent=2)
            f.write("\n")
        print(json.dumps(rec), flush=True)


if __name__ == "__main__":
    main()
