"""Run an exported MCX input (`skin export mcx`) in pmcxcl (MCX on OpenCL) and print its reflectance.

Usage: python mcx_run.py INPUT.json [PHOTONS]

The JSON input is turned into pmcxcl's dictionary as MCX reads it: the volume filled with label 2
(`Grid` Tag 2), z-slices 1–5 set to label 1 (`ZLayers`), media rows as [mua, mus, g, n] (mm⁻¹),
`LengthUnit` as unitinmm, the pencil source and the one detector, origin at 0 (`OriginType` 1),
index mismatch on. The reflectance is Σ w0 exp(−Σᵢ muaᵢ Lᵢ) / Photons over the detected photons,
Lᵢ the partial path in medium i (MCX saves it in voxel units: × unitinmm for mm); it is per photon
entering, as MCX launches inside the first voxel. Its standard error is the spread of the per-photon
contributions (0 for undetected photons) over √Photons. Prints one JSON object: {"engine",
"version", "lambda_nm", "reflectance", "stderr", "photons", "detected"}.
"""

import json
import sys

import numpy as np
import pmcxcl


def main():
    path = sys.argv[1]
    with open(path, encoding="utf-8") as f:
        mcx = json.load(f)
    photons = int(sys.argv[2]) if len(sys.argv) > 2 else int(mcx["Session"]["Photons"])
    dom = mcx["Domain"]
    nx, ny, nz = dom["Dim"]
    vol = np.full((nx, ny, nz), 2, dtype=np.uint8)
    for shape in mcx["Shapes"]:
        for z0, z1, tag in shape.get("ZLayers", []):
            vol[:, :, z0 - 1:z1] = tag
    prop = np.array([[m["mua"], m["mus"], m["g"], m["n"]] for m in dom["Media"]], dtype=np.float32)
    src = mcx["Optode"]["Source"]
    det = mcx["Optode"]["Detector"][0]
    unit = float(dom["LengthUnit"])
    fwd = mcx["Forward"]
    cfg = {
        "nphoton": photons,
        "vol": vol,
        "prop": prop,
        "unitinmm": unit,
        "tstart": fwd["T0"],
        "tend": fwd["T1"],
        "tstep": fwd["Dt"],
        "srcpos": src["Pos"],
        "srcdir": src["Dir"],
        "srctype": src["Type"],
        "detpos": [[*det["Pos"], det["R"]]],
        "issrcfrom0": int(dom["OriginType"]),
        "isreflect": int(mcx["Session"]["DoMismatch"]),
        "savedetflag": "dpw",
        "maxdetphoton": photons,
        "seed": int(mcx["Session"]["RNGSeed"]),
        "autopilot": 1,
        "gpuid": 1,
    }
    res = pmcxcl.run(cfg)
    # With savedetflag "dpw" pmcxcl returns one row per saved field: detector id, the partial path
    # in each medium (media 1 … n), the initial weight.
    detp = np.asarray(res["detp"], dtype=np.float64)
    n_media = prop.shape[0] - 1
    if detp.ndim != 2 or detp.shape[0] != n_media + 2:
        raise SystemExit(f"unexpected detected-photon array of shape {detp.shape}")
    ppath = detp[1:1 + n_media].T
    w0 = detp[1 + n_media]
    mua = prop[1:, 0].astype(np.float64)
    weights = w0 * np.exp(-(ppath * unit) @ mua)
    r = weights.sum() / photons
    second = (weights * weights).sum() / photons
    stderr = np.sqrt(max(second - r * r, 0.0) / photons)
    print(json.dumps({
        "engine": "mcx",
        "version": "pmcxcl " + pmcxcl.__version__,
        "id": mcx["Session"]["ID"],
        "reflectance": float(r),
        "stderr": float(stderr),
        "photons": photons,
        "detected": int(w0.size),
    }))


if __name__ == "__main__":
    main()
