"""The lips of the built-in head through `spectral_skin.maps`: their residual and blood fraction
with one skin, with the thin-epidermis skin's C_h capped at 0.1, and with its default range.

The lips are the texels with a* > 27 and 40 < L* < 56 in the texture as given (linear Rec.709 →
XYZ → CIELAB, D65). Run from the repository root after `pip install ./python pillow`:

    python python/examples/maps_lips.py render/assets/Map-COL.jpg
"""

import sys
import time

import numpy as np
from PIL import Image

import spectral_skin as ss

# Linear Rec.709 → XYZ (D65), IEC 61966-2-1.
TO_XYZ = np.array(
    [[0.4124564, 0.3575761, 0.1804375], [0.2126729, 0.7151522, 0.0721750], [0.0193339, 0.1191920, 0.9503041]]
)


def linear(srgb8: np.ndarray) -> np.ndarray:
    c = srgb8.astype(np.float64) / 255.0
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def main(path: str) -> None:
    rgb = linear(np.asarray(Image.open(path).convert("RGB")))
    lab = ss.lab(xyz=rgb @ TO_XYZ.T)
    lips = (lab[..., 1] > 27) & (lab[..., 0] > 40) & (lab[..., 0] < 56)
    print(f"{path}: {rgb.shape[1]}×{rgb.shape[0]}, lips {lips.sum()} texels")
    print("| skins | lips in gamut | lips median / p95 ΔE2000 | lips C_h median | all in gamut | s |")
    print("|---|---|---|---|---|---|")
    for name, kw in [
        ("one skin (`thin_epidermis=False`)", dict(thin_epidermis=False)),
        ("thin skin, C_h ≤ 0.1 (`thin_hemoglobin_max=0.1`)", dict(thin_hemoglobin_max=0.1)),
        ("thin skin, C_h ≤ 0.25 (default)", dict()),
    ]:
        t = time.perf_counter()
        m = ss.maps(rgb, exposure="auto-rgb", **kw)
        dt = time.perf_counter() - t
        de = m["delta_e"][lips]
        print(
            f"| {name} | {100 * m['in_gamut'][lips].mean():.1f} % | {np.median(de):.2f} / "
            f"{np.percentile(de, 95):.2f} | {np.median(m['hemoglobin'][lips]):.3f} | "
            f"{100 * m['in_gamut'].mean():.1f} % | {dt:.1f} |"
        )


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "render/assets/Map-COL.jpg")
