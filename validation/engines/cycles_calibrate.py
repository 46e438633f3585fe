"""Measure Cycles' subsurface reflectance against the Principled BSDF's Base Color.

Usage: python cycles_calibrate.py OUT.csv SPP [PX]

On the `slab` scene of `cycles_common` (normal view, uniform white sky), a Principled BSDF with
Subsurface Weight 1 and the settings `skin export blender` writes (IOR 1.4, Roughness √0.3,
Specular IOR Level 0.5, Subsurface Anisotropy 0.9, radius 1 mm per channel; the slab is 50 mm
thick, so the total does not depend on the radius) is rendered for grey Base Colors c, for both Random Walk methods. The subsurface part is the pixel minus the pixel at
c = 0 (the specular face alone). Writes one CSV row per (method, c): the measured subsurface
reflectance, its standard error (over pixels, both renders), the samples and Blender's version.
"""

import sys

import bpy
import numpy as np

import cycles_common as cc

METHODS = ("RANDOM_WALK", "RANDOM_WALK_SKIN")
IOR = 1.4
ROUGHNESS = 0.3 ** 0.5
SPECULAR_IOR_LEVEL = 0.5
ANISOTROPY = 0.0
# Grey Base Colors, one per render: Cycles guides every channel's walk by the largest channel's
# albedo, so a colour's channels are not independent measurements of the grey curve.
LADDER = (0.005, 0.01, 0.02, 0.03, 0.04, 0.05, 0.06, 0.08, 0.1, 0.125, 0.15, 0.175, 0.2, 0.25,
          0.3, 0.35, 0.4, 0.45, 0.5, 0.55, 0.6, 0.65, 0.7, 0.75)


def principled(method, base):
    mat = bpy.data.materials.new(f"calib_{method}")
    mat.use_nodes = True
    p = mat.node_tree.nodes["Principled BSDF"]
    p.subsurface_method = method
    p.inputs["Base Color"].default_value = (*base, 1.0)
    p.inputs["Subsurface Weight"].default_value = 1.0
    p.inputs["Subsurface Radius"].default_value = (1.0, 1.0, 1.0)
    p.inputs["Subsurface Scale"].default_value = 1.0
    if "Subsurface IOR" in p.inputs:  # Random Walk (Skin) only
        p.inputs["Subsurface IOR"].default_value = IOR
    p.inputs["Subsurface Anisotropy"].default_value = ANISOTROPY
    p.inputs["IOR"].default_value = IOR
    p.inputs["Roughness"].default_value = ROUGHNESS
    p.inputs["Specular IOR Level"].default_value = SPECULAR_IOR_LEVEL
    return mat


def measure(method, base, spp, px, seed):
    scene = cc.reset(spp, px, seed=seed)
    cc.light_paths(scene, 16)
    cc.slab(scene, principled(method, base))
    return cc.mean_and_stderr(cc.render(scene))


def main():
    out, spp = sys.argv[1], int(sys.argv[2])
    px = int(sys.argv[3]) if len(sys.argv) > 3 else 16
    rows = []
    for method in METHODS:
        spec, spec_se = measure(method, (0.0, 0.0, 0.0), 4 * spp, px, 7)
        print(method, "specular", spec, spec_se, file=sys.stderr, flush=True)
        for k, c in enumerate(LADDER):
            mean, se = measure(method, (c, c, c), spp, px, 100 + k)
            rows.append((method, c, float(mean[0] - spec[0]), float(np.hypot(se[0], spec_se[0]))))
            print(method, c, mean[0] - spec[0], se[0], file=sys.stderr, flush=True)
    with open(out, "w", encoding="utf-8") as f:
        f.write(f"# Cycles {bpy.app.version_string} (bpy wheel), CPU, {spp} spp, {px}x{px} px; "
                f"slab scene of validation/engines/cycles_common.py; IOR {IOR}, roughness "
                f"{ROUGHNESS:.6f}, Specular IOR Level {SPECULAR_IOR_LEVEL}, Subsurface Anisotropy "
                f"{ANISOTROPY}\n")
        f.write("method,base_color,subsurface_reflectance,stderr\n")
        for method, c, r, se in sorted(rows):
            f.write(f"{method},{c:.4f},{r:.6f},{se:.6f}\n")


if __name__ == "__main__":
    main()
