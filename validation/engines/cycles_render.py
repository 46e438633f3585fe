"""Render the script `skin export blender` writes, in Cycles, and print its mean pixel.

Usage: python cycles_render.py SKIN.py SCENE METHOD SPP
SCENE is `slab` or `sphere` (the scenes of `cycles_common`) with the script's
subsurface_material(METHOD), `volume` (the script's volume_slab() seen straight down; METHOD is
ignored) or `volume_white` (what the `sphere` scene averages, on that slab: the camera at the four
Gauss–Legendre nodes of t = μ² on [t₀, 1], t₀ = 1 − 0.95² the sphere mask's edge, each pixel minus
the exact Fresnel reflectance F(μ) of the smooth face; the mean over the projected disc of a large
sphere under a white sky is the mean of R(μ) over t, since a disc's area is uniform in μ²).

For the Principled scenes the same scene is rendered again with Base Color 0 (the specular face
alone) and the subsurface part is the difference. Prints one JSON object: {"engine", "version",
"scene", "method", "mean", "stderr", "specular", "pixels"}; `mean` is the subsurface part (Principled)
or the whole pixel (volume), per RGB channel, with its standard error over pixels.
"""

import json
import os
import runpy
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import cycles_common as cc  # noqa: E402


def principled(skin, scene_name, method, spp, base_zero, seed):
    px = 16 if scene_name == "slab" else cc.SPHERE_SIDE_PX
    scene = cc.reset(spp, px, seed=seed)
    cc.light_paths(scene, 16)
    mat = skin["subsurface_material"](method)
    if base_zero:
        for node in mat.node_tree.nodes:
            if node.bl_idname == "ShaderNodeBsdfPrincipled":
                node.inputs["Base Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    getattr(cc, scene_name)(scene, mat)
    pixels = cc.render(scene)
    if scene_name == "sphere":
        pixels = pixels[cc.disc_mask(pixels)]
    return cc.mean_and_stderr(pixels), int(pixels.size // 3)


def fresnel(mu, eta):
    """Unpolarised Fresnel reflectance from air onto index `eta` at incidence cosine `mu`."""
    sin_t2 = (1.0 - mu * mu) / (eta * eta)
    mu_t = np.sqrt(1.0 - sin_t2)
    rs = (mu - eta * mu_t) / (mu + eta * mu_t)
    rp = (eta * mu - mu_t) / (eta * mu + mu_t)
    return 0.5 * (rs * rs + rp * rp)


def volume_view(path, spp, mu, seed):
    """Mean pixel and standard error of the volumetric slab seen at incidence cosine `mu`."""
    scene = cc.reset(spp, 16, seed=seed)
    skin = runpy.run_path(path, run_name="skin_export")
    skin["volume_slab"](scene)
    cam = cc.camera(scene, 10.0, 1.0)
    sin = np.sqrt(1.0 - mu * mu)
    cam.location = (0.0, -10.0 * sin, 10.0 * mu)
    cam.rotation_euler = (float(np.arccos(mu)), 0.0, 0.0)
    return cc.mean_and_stderr(cc.render(scene)), skin["VALUES"]["volume"]["glass_ior"]


def main():
    path, scene_name, method, spp = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4])
    # Loading the script defines its functions without running its __main__ block; every scene
    # below starts from an empty file, so the functions are looked up again after each reset.
    if scene_name == "volume":
        ((mean, se), _), n = volume_view(path, spp, 1.0, 3), 256
        spec = np.zeros(3)
    elif scene_name == "volume_white":
        # Mean of R(√t) over t = μ² ∈ [t₀, 1]: 4-point Gauss–Legendre.
        nodes, weights = np.polynomial.legendre.leggauss(4)
        t0 = 1.0 - cc.SPHERE_MASK ** 2
        mean, var, spec, n = np.zeros(3), np.zeros(3), np.zeros(3), 0
        for k, (x, w) in enumerate(zip(nodes, weights)):
            mu = float(np.sqrt(t0 + (1.0 - t0) * 0.5 * (x + 1.0)))
            (m, e), eta = volume_view(path, spp, mu, 10 + k)
            f = fresnel(mu, eta)
            mean += 0.5 * w * (m - f)
            var += (0.5 * w * e) ** 2
            spec += 0.5 * w * f
            n += 256
        se = np.sqrt(var)
    else:
        skin = runpy.run_path(path, run_name="skin_export")
        (full, se_full), n = principled(skin, scene_name, method, spp, False, 5)
        skin = runpy.run_path(path, run_name="skin_export")
        (spec, se_spec), _ = principled(skin, scene_name, method, 4 * spp, True, 6)
        mean, se = full - spec, np.hypot(se_full, se_spec)
    print(json.dumps({
        "engine": "cycles",
        "version": bpy.app.version_string,
        "scene": scene_name,
        "method": method,
        "mean": [float(x) for x in mean],
        "stderr": [float(x) for x in se],
        "specular": [float(x) for x in spec],
        "pixels": n,
        "radius_mm": cc.SPHERE_RADIUS_MM,
        "mask": cc.SPHERE_MASK,
        "side": cc.SPHERE_SIDE_PX,
    }))


if __name__ == "__main__":
    main()
