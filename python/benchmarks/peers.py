"""spectral_skin side by side with its Python peers, each on one core.

    python3 -m venv /tmp/peers && /tmp/peers/bin/pip install ./python iadpython scipy skinoptics colour-science
    taskset -c 0 /tmp/peers/bin/python python/benchmarks/peers.py [--spectra 1000] [--exact-spectra 20]

1. Adding-doubling totals of the same slab against iadpython (values and time per slab).
2. The formulas both packages implement (eumelanin σa = 6.6·10¹⁰ λ^−3.33, the baseline
   0.0244 + 8.53 e^−(λ−154)/66.2, mm⁻¹) against skinoptics, and colour (CIELAB, CIEDE2000, ITA°)
   against skinoptics and colour-science.
3. Fitting measured spectra (the ISSA subset in validation/data, SCI): spectra per second.

Prints one Markdown table per part; the times are the best of `--repeat` runs of each call.
"""

from __future__ import annotations

import argparse
import csv
import pathlib
import time
import warnings

import numpy as np

import spectral_skin as ss

ROOT = pathlib.Path(__file__).resolve().parents[2]


def best(f, repeat: int) -> float:
    """Best wall time of `repeat` calls of f, seconds."""
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        f()
        times.append(time.perf_counter() - t)
    return min(times)


def slabs() -> list[tuple[float, float, float, float]]:
    """(albedo a, optical thickness b, g, n) of the compared slabs: skin-like and textbook ones."""
    return [
        (0.99, 10.0, 0.9, 1.4),
        (0.9, 1.0, 0.9, 1.4),
        (0.5, 2.0, 0.5, 1.4),
        (0.999, 100.0, 0.9, 1.4),
        (0.95, 5.0, 0.0, 1.0),
        (0.8, 0.5, 0.8, 1.33),
    ]


def part_adding_doubling(repeat: int) -> None:
    import iadpython as iad

    print("\n## Adding-doubling totals of one slab (d = 1 mm, in air), normal incidence, 16 points each\n")
    print("| a | b | g | n | R total (iadpython) | R total (spectral_skin) | T (iadpython) | T (spectral_skin) | |ΔR| | |ΔT| |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    worst = 0.0
    for a, b, g, n in slabs():
        s = iad.Sample(a=a, b=b, g=g, d=1.0, n=n, n_above=1.0, n_below=1.0, quad_pts=16)
        ur1, ut1, _, _ = s.rt()
        mu_t = b / 1.0
        t = ss.adding_doubling(mu_t * (1 - a), mu_t * a, g, 1.0, n=n, quadrature_points=16, threads=1)
        r_ss = float(t.diffuse_reflectance + t.specular_reflectance)
        t_ss = float(t.transmittance)
        dr, dt = abs(r_ss - ur1), abs(t_ss - ut1)
        worst = max(worst, dr, dt)
        print(f"| {a} | {b} | {g} | {n} | {ur1:.5f} | {r_ss:.5f} | {ut1:.5f} | {t_ss:.5f} | {dr:.1e} | {dt:.1e} |")
    print(f"\nlargest difference {worst:.1e}")

    # Time: the same 100 slabs (a spread of albedos) through each, one core.
    albedo = np.linspace(0.5, 0.999, 100)
    b, g, n = 5.0, 0.9, 1.4

    def iad_run():
        iad.Sample(a=albedo, b=b, g=g, d=1.0, n=n, n_above=1.0, n_below=1.0, quad_pts=16).rt()

    def ss_run():
        ss.adding_doubling(b * (1 - albedo), b * albedo, g, 1.0, n=n, quadrature_points=16, threads=1)

    t_iad = best(iad_run, repeat)
    t_ss = best(ss_run, repeat)
    print("\n| 100 slabs, 16 points, one core | iadpython | spectral_skin | ratio |")
    print("|---|---|---|---|")
    print(f"| time | {t_iad * 1e3:.1f} ms | {t_ss * 1e3:.2f} ms | {t_iad / t_ss:.0f}× |")


def part_skinoptics(repeat: int) -> None:
    import colour
    from skinoptics import absorption_coefficient as sk_abs
    from skinoptics import colors as sk_col

    print("\n## Shared formulas and colour against skinoptics and colour-science\n")
    rng = np.random.default_rng(1)
    wl = rng.uniform(400.0, 1000.0, 100_000)
    # spectral_skin's epidermis σa at C_m = 1, β_m = 1 is eumelanin's, at C_m = 0 the baseline.
    ours_mel = ss.coefficients(wl, melanin=1.0, eumelanin=1.0).sigma_a_epidermis_per_mm
    ours_base = ss.coefficients(wl, melanin=0.0).sigma_a_epidermis_per_mm
    rel_mel = np.max(np.abs(ours_mel / sk_abs.mua_mel_Jacques(wl) - 1))
    rel_base = np.max(np.abs(ours_base / sk_abs.mua_baseline(wl) - 1))

    n = 100_000
    lab1 = np.column_stack([rng.uniform(20, 80, n), rng.uniform(-10, 30, n), rng.uniform(1, 40, n)])
    lab2 = lab1 + rng.normal(0, 3, (n, 3))
    de_ours = ss.delta_e_2000(lab1, lab2)
    de_cs = colour.delta_E(lab1, lab2, method="CIE 2000")
    # skinoptics 0.0.8's Delta_E_00 given arrays returns values that differ from its own scalar
    # calls; its scalar calls are the reference, on the first 2,000 pairs.
    k = 2_000
    de_sk = np.array([sk_col.Delta_E_00(*lab1[i], *lab2[i]) for i in range(k)])
    de_sk_vec = sk_col.Delta_E_00(*lab1[:k].T, *lab2[:k].T)
    ita_ours = ss.ita(lab1)  # b* ≥ 1: no floor of b* applies
    ita_sk = sk_col.ITA(lab1[:, 0], lab1[:, 2])
    xyz = colour.Lab_to_XYZ(lab1)
    lab_ours = ss.lab(xyz=xyz)
    # The same white: spectral_skin's D65 (the CIE tables summed at 1 nm) as colour-science's illuminant.
    white = ss.xyz(np.arange(400.0, 701.0, 10.0), np.ones(31))
    lab_cs = colour.XYZ_to_Lab(xyz, illuminant=colour.XYZ_to_xy(white))

    t = {}
    t["eumelanin σa, 1e5 λ: spectral_skin"] = best(lambda: ss.coefficients(wl, melanin=1.0, eumelanin=1.0), repeat)
    t["eumelanin σa, 1e5 λ: skinoptics"] = best(lambda: sk_abs.mua_mel_Jacques(wl), repeat)
    t["ΔE00, 1e5 pairs: spectral_skin"] = best(lambda: ss.delta_e_2000(lab1, lab2), repeat)
    t["ΔE00, 1e5 pairs: colour-science"] = best(lambda: colour.delta_E(lab1, lab2, method="CIE 2000"), repeat)
    t["ΔE00, 2,000 pairs: spectral_skin"] = best(lambda: ss.delta_e_2000(lab1[:k], lab2[:k]), repeat)
    t["ΔE00, 2,000 pairs: skinoptics (scalar calls)"] = best(
        lambda: [sk_col.Delta_E_00(*lab1[i], *lab2[i]) for i in range(k)], 1
    )
    t["XYZ→Lab, 1e5: spectral_skin"] = best(lambda: ss.lab(xyz=xyz), repeat)
    t["XYZ→Lab, 1e5: colour-science"] = best(lambda: colour.XYZ_to_Lab(xyz), repeat)
    t["ITA°, 1e5: spectral_skin"] = best(lambda: ss.ita(lab1), repeat)
    t["ITA°, 1e5: skinoptics"] = best(lambda: sk_col.ITA(lab1[:, 0], lab1[:, 2]), repeat)

    print("| quantity | largest difference |")
    print("|---|---|")
    print(f"| eumelanin σa (1e5 λ in 400–1000 nm) vs skinoptics `mua_mel_Jacques` | {rel_mel:.1e} relative |")
    print(f"| baseline σa vs skinoptics `mua_baseline` | {rel_base:.1e} relative |")
    print(f"| CIEDE2000, 2,000 pairs vs skinoptics `Delta_E_00` (scalar calls) | {np.max(np.abs(de_ours[:k] - de_sk)):.1e} |")
    print(f"| CIEDE2000, 2,000 pairs vs skinoptics `Delta_E_00` (array call) | {np.max(np.abs(de_ours[:k] - de_sk_vec)):.1e} |")
    print(f"| CIEDE2000, 1e5 pairs vs colour-science `delta_E(…, 'CIE 2000')` | {np.max(np.abs(de_ours - de_cs)):.1e} |")
    print(f"| ITA° (b* ≥ 1) vs skinoptics `ITA` | {np.max(np.abs(ita_ours - ita_sk)):.1e} ° |")
    print(f"| CIELAB from XYZ vs colour-science `XYZ_to_Lab` (same white) | {np.max(np.abs(lab_ours - lab_cs)):.1e} |")
    print("\n| call, one core | time |")
    print("|---|---|")
    for name, v in t.items():
        print(f"| {name} | {v * 1e3:.2f} ms |")


def issa_spectra() -> tuple[np.ndarray, np.ndarray]:
    rows = []
    wl = None
    for name in ("issa_explore.csv", "issa_heldout.csv"):
        with open(ROOT / "validation" / "data" / name) as f:
            lines = [ln for ln in f if not ln.startswith("#")]
        reader = csv.reader(lines)
        header = next(reader)
        cols = [i for i, h in enumerate(header) if h.startswith("r") and h[1:].isdigit()]
        wl = np.array([float(header[i][1:]) for i in cols])
        rows += [[float(r[i]) for i in cols] for r in reader if r]
    return wl, np.array(rows)


def part_fit(n_spectra: int, n_exact: int) -> None:
    print("\n## Fitting measured spectra (ISSA, SCI, 400–700 nm every 10 nm)\n")
    wl, spectra = issa_spectra()
    reps = int(np.ceil(n_spectra / len(spectra)))
    batch = np.tile(spectra, (reps, 1))[:n_spectra]
    print("| fit | spectra | threads | time | spectra/s | median RMS |")
    print("|---|---|---|---|---|---|")
    for method, count in (("multipole", n_spectra), ("exact", n_exact)):
        for threads in (1, 2):
            t = time.perf_counter()
            fit = ss.fit_spectrum(wl, batch[:count], geometry="sci", method=method, threads=threads)
            dt = time.perf_counter() - t
            print(
                f"| `method=\"{method}\", geometry=\"sci\"` | {count} | {threads} | {dt:.1f} s | "
                f"{count / dt:.2f} | {np.median(fit.rms):.4f} |"
            )


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--spectra", type=int, default=1000)
    p.add_argument("--exact-spectra", type=int, default=20)
    p.add_argument("--repeat", type=int, default=5)
    p.add_argument("--skip-fit", action="store_true")
    p.add_argument("--only-adding-doubling", action="store_true")
    args = p.parse_args()
    warnings.simplefilter("ignore")
    part_adding_doubling(args.repeat)
    if args.only_adding_doubling:
        return
    part_skinoptics(args.repeat)
    if not args.skip_fit:
        part_fit(args.spectra, args.exact_spectra)


if __name__ == "__main__":
    main()
