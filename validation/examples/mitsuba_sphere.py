"""Mitsuba 3's side of `mitsuba_side_by_side` (validation/examples/mitsuba_side_by_side.rs).

Renders the matched scene — a homogeneous sphere (the OBJ given, smooth dielectric n, HG phase g,
sigma_a and sigma_s per scene unit = mm) under a constant sky of radiance 1, seen by a perspective
camera at (0, 0, distance) looking at the origin — with Mitsuba's volumetric path tracer `volpath`
(no depth limit), a box pixel filter and the independent sampler, once per seed. Each image is
written as raw little-endian f32 (row-major, `side` × `side` radiance values) to OUT_PREFIX-SEED.f32,
and for each seed a line `seed S cpu_s T` gives the process CPU seconds of `mi.render` alone (after
one warm-up render, so that the LLVM variant's kernel compilation is not counted).

python mitsuba_sphere.py VARIANT THREADS RR_DEPTH OBJ SIDE SPP DISTANCE FOV_DEG SIGMA_A SIGMA_S G
       ETA OUT_PREFIX [--dermis INNER_OBJ SIGMA_A SIGMA_S] SEED...

With `--dermis`, the sphere is two-layer: SIGMA_A and SIGMA_S are the epidermis', and INNER_OBJ,
an index-matched (`null`) shape inside, holds the dermis medium (its own sigma_a and sigma_s).

RR_DEPTH is volpath's `rr_depth`, the bounce from which Russian roulette may end a path (its
default 5; a huge value turns roulette off).
"""

import sys
import time

import drjit as dr
import mitsuba as mi
import numpy as np


def main(argv):
    variant, threads, rr_depth = argv[1], int(argv[2]), int(argv[3])
    obj, side, spp = argv[4], int(argv[5]), int(argv[6])
    distance, fov, sigma_a, sigma_s, g, eta = map(float, argv[7:13])
    out_prefix, rest = argv[13], argv[14:]
    inner = None
    if rest and rest[0] == "--dermis":
        inner = (rest[1], float(rest[2]), float(rest[3]))
        rest = rest[4:]
    seeds = [int(s) for s in rest]
    mi.set_variant(variant)
    mi.set_log_level(mi.LogLevel.Error)
    dr.set_thread_count(threads)
    def medium(sa, ss):
        return {
            "type": "homogeneous",
            "sigma_t": sa + ss,
            "albedo": ss / (sa + ss),
            "phase": {"type": "hg", "g": g},
        }

    def scene(seed, samples):
        shapes = {}
        if inner is not None:
            shapes["dermis"] = {
                "type": "obj",
                "filename": inner[0],
                "bsdf": {"type": "null"},
                "interior": medium(inner[1], inner[2]),
                "exterior": medium(sigma_a, sigma_s),
            }
        return mi.load_dict({
            "type": "scene",
            "integrator": {"type": "volpath", "max_depth": -1, "rr_depth": rr_depth},
            "sensor": {
                "type": "perspective",
                "fov": fov,
                "fov_axis": "x",
                "to_world": mi.ScalarTransform4f().look_at(
                    origin=[0, 0, distance], target=[0, 0, 0], up=[0, 1, 0]),
                "film": {"type": "hdrfilm", "width": side, "height": side,
                         "rfilter": {"type": "box"}},
                "sampler": {"type": "independent", "sample_count": samples, "seed": seed},
            },
            "sky": {"type": "constant", "radiance": {"type": "rgb", "value": [1.0, 1.0, 1.0]}},
            "sphere": {
                "type": "obj",
                "filename": obj,
                "bsdf": {"type": "dielectric", "int_ior": eta, "ext_ior": 1.0},
                "interior": medium(sigma_a, sigma_s),
            },
            **shapes,
        })

    warm = scene(0, 1)
    mi.render(warm, spp=1)
    for seed in seeds:
        s = scene(seed, spp)
        t0 = time.process_time()
        img = mi.render(s, spp=spp, seed=seed)
        dr.eval(img)
        img = np.array(img, dtype=np.float64)
        cpu = time.process_time() - t0
        # Luminance of grey RGB, or the mono variants' single channel.
        y = img[..., 1] if img.ndim == 3 and img.shape[2] >= 3 else img.reshape(side, side)
        np.asarray(y, dtype="<f4").tofile(f"{out_prefix}-{seed}.f32")
        print(f"seed {seed} cpu_s {cpu:.4f}", flush=True)


if __name__ == "__main__":
    main(sys.argv)
