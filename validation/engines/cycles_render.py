"""Render the script `skin export blender` writes, in Cycles, and print its mean pixel.

Usage: python cycles_render.py SKIN.py SCENE METHOD SPP
SCENE is `slab` or `sphere` (the scenes of `cycles_common`) with the script's
subsurface_material(METHOD), or `volume` (the script's volume_slab(); METHOD is ignored).

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
    px = 16 if scene_name == "slab" else 48
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


def main():
    path, scene_name, method, spp = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4])
    # Loading the script defines its functions without running its __main__ block; every scene
    # below starts from an empty file, so the functions are looked up again after each reset.
    if scene_name == "volume":
        scene = cc.reset(spp, 16, seed=3)
        skin = runpy.run_path(path, run_name="skin_export")
        skin["volume_slab"](scene)
        cc.camera(scene, 10.0, 1.0)
        (mean, se), n = cc.mean_and_stderr(cc.render(scene)), 256
        spec = np.zeros(3)
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
    }))


if __name__ == "__main__":
    main()
