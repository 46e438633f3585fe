"""Render an exported Mitsuba 3 scene (`skin export mitsuba --scene`) and print its mean pixel.

Usage: python mitsuba_render.py SCENE.xml VARIANT SPP
Prints one JSON object: {"engine", "version", "variant", "mean": [...], "stderr": [...], "nan": n}.
The film's pixels are independent estimates, so the standard error of the mean is their spread
over the square root of their count.
"""

import json
import sys

import mitsuba as mi
import numpy as np


def main() -> None:
    path, variant, spp = sys.argv[1], sys.argv[2], int(sys.argv[3])
    mi.set_variant(variant)
    mi.set_log_level(mi.LogLevel.Error)
    scene = mi.load_file(path)
    image = np.array(mi.render(scene, spp=spp), dtype=np.float64)
    pixels = image.reshape(-1, image.shape[-1]) if image.ndim == 3 else image.reshape(-1, 1)
    nan = int(np.isnan(pixels).sum())
    mean = np.nanmean(pixels, axis=0)
    stderr = np.nanstd(pixels, axis=0, ddof=1) / np.sqrt(pixels.shape[0])
    print(json.dumps({
        "engine": "mitsuba",
        "version": mi.__version__,
        "variant": variant,
        "mean": mean.tolist(),
        "stderr": stderr.tolist(),
        "nan": nan,
    }))


if __name__ == "__main__":
    main()
