"""Where the Cycles sphere's excess comes from: the Principled subsurface part of the script
`skin export blender` writes, on spheres of several radii and on the flat slab.

Usage: python cycles_sphere_study.py SKIN.py METHOD SPP WHAT...
WHAT is `slab` (normal view), `slabwhite` (the slab seen at the four Gauss-Legendre nodes of t = mu^2
over the sphere mask's range, weighted as the disc weights them: a sphere of infinite radius) or
`sphereR` (a sphere of radius R mm, e.g. `sphere20`). The environment variable ROUGH overrides the
Principled Roughness. Prints one line `RESULT {json}`, the subsurface part per RGB channel.
"""

import json
import os
import runpy
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import cycles_common as cc  # noqa: E402

path, method, spp = sys.argv[1], sys.argv[2], int(sys.argv[3])
what = sys.argv[4:]

def principled_px(build, base_zero, seed, px, spp):
    skin = runpy.run_path(path, run_name="skin_export")
    scene = cc.reset(spp, px, seed=seed)
    cc.light_paths(scene, 16)
    mat = skin["subsurface_material"](method)
    rough = os.environ.get("ROUGH")
    if rough is not None:
        for node in mat.node_tree.nodes:
            if node.bl_idname == "ShaderNodeBsdfPrincipled":
                node.inputs["Roughness"].default_value = float(rough)
    if base_zero:
        for node in mat.node_tree.nodes:
            if node.bl_idname == "ShaderNodeBsdfPrincipled":
                node.inputs["Base Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    build(scene, mat)
    return cc.render(scene)

out = {}
for w in what:
    if w.startswith("sphere"):
        r = float(w[6:])
        cc.SPHERE_RADIUS_MM = r
        full = principled_px(cc.sphere, False, 5, 48, spp)
        spec = principled_px(cc.sphere, True, 6, 48, spp)
        m = cc.disc_mask(full)
        out[w] = list(full[m].mean(0) - spec[m].mean(0))
    elif w == "slab":
        full = principled_px(cc.slab, False, 5, 16, spp).reshape(-1, 3).mean(0)
        spec = principled_px(cc.slab, True, 6, 16, spp).reshape(-1, 3).mean(0)
        out[w] = list(full - spec)
    elif w == "slabwhite":
        nodes, weights = np.polynomial.legendre.leggauss(4)
        t0 = 1.0 - cc.SPHERE_MASK ** 2
        acc = np.zeros(3)
        per = []
        for k, (x, wt) in enumerate(zip(nodes, weights)):
            mu = float(np.sqrt(t0 + (1.0 - t0) * 0.5 * (x + 1.0)))
            def build(scene, mat, mu=mu):
                cc.slab(scene, mat)
                cam = scene.camera
                s = np.sqrt(1 - mu * mu)
                cam.location = (0.0, -10.0 * s, 10.0 * mu)
                cam.rotation_euler = (float(np.arccos(mu)), 0.0, 0.0)
            full = principled_px(build, False, 10 + k, 16, spp).reshape(-1, 3).mean(0)
            spec = principled_px(build, True, 20 + k, 16, spp).reshape(-1, 3).mean(0)
            per.append([mu] + list(full - spec))
            acc += 0.5 * wt * (full - spec)
        out[w] = list(acc)
        out["slab_angles"] = per
print("RESULT", json.dumps({"file": path, "method": method, **out}))
