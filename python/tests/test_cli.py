"""Every function against the `skin` binary's numbers for the same skin, to the printed precision."""

from __future__ import annotations

import csv
import io
import json
import re

import numpy as np
import pytest

import spectral_skin as ss

# A skin away from every default, so a parameter that is dropped on the way shows.
SKIN = dict(melanin=0.12, eumelanin=0.7, hemoglobin=0.03, oil=0.3)
FLAGS = ["--melanin", "0.12", "--eumelanin", "0.7", "--hemoglobin", "0.03", "--oil", "0.3"]
# Printed with 6 decimals: half a unit in the last place, plus the float's own rounding.
HALF_ULP_6 = 5.000001e-7


def _rows(text: str) -> tuple[list[str], np.ndarray]:
    reader = csv.reader(io.StringIO(text))
    header = next(reader)
    return header, np.array([[float(v) for v in row] for row in reader])


def _spectrum(cli, method: str, *extra: str) -> tuple[np.ndarray, str]:
    out, err = cli("spectrum", *FLAGS, "--method", method, *extra)
    header, rows = _rows(out)
    assert header[0] == "lambda_nm" and header[-1] == "diffuse_reflectance"
    return rows, err


@pytest.mark.parametrize("method", ["exact", "multipole"])
def test_coefficients_and_reflectance_match_skin_spectrum(cli, method):
    rows, _ = _spectrum(cli, method, "--step", "25")
    wl = rows[:, 0]
    c = ss.coefficients(wl, **SKIN)
    np.testing.assert_allclose(c.sigma_a_epidermis_per_mm, rows[:, 1], rtol=0, atol=HALF_ULP_6)
    np.testing.assert_allclose(c.sigma_a_dermis_per_mm, rows[:, 2], rtol=0, atol=HALF_ULP_6)
    np.testing.assert_allclose(c.sigma_s_reduced_per_mm, rows[:, 3], rtol=0, atol=HALF_ULP_6)
    r = ss.diffuse_reflectance(wl, method=method, **SKIN)
    np.testing.assert_allclose(r, rows[:, 4], rtol=0, atol=HALF_ULP_6)


def test_lab_and_ita_match_skin_spectrum(cli):
    rows, err = _spectrum(cli, "multipole")
    m = re.search(r"lab L\*=(\S+) a\*=(\S+) b\*=(\S+) ITA°=(\S+)", err)
    assert m, err
    printed = np.array([float(v) for v in m.groups()])
    wl = rows[:, 0]
    r = ss.diffuse_reflectance(wl, method="multipole", **SKIN)
    lab = ss.lab(wl, r)
    np.testing.assert_allclose(lab, printed[:3], rtol=0, atol=0.005 + 1e-9)
    assert abs(float(ss.ita(lab)) - printed[3]) <= 0.05 + 1e-9
    hex_ = re.search(r"srgb (#[0-9a-f]{6})", err).group(1)
    assert ss.srgb(lab) == hex_


def test_sci_adds_a_surface_term_linear_in_oil():
    # SCI − SCE = ρ_s·a(cos 8°): independent of λ, proportional to the oiliness ρ_s, and for the
    # rough lobe (η = 1.4) near the smooth Fresnel reflectance F(0) = ((η − 1)/(η + 1))² = 0.0278.
    wl = [450.0, 650.0]
    sce = ss.diffuse_reflectance(wl, geometry="sce", method="multipole", **SKIN)
    sci = ss.diffuse_reflectance(wl, geometry="sci", method="multipole", **SKIN)
    d = sci - sce
    assert d[0] == pytest.approx(d[1], rel=1e-12)
    skin2 = dict(SKIN, oil=0.6)
    d2 = ss.diffuse_reflectance(wl, geometry="sci", method="multipole", **skin2) - ss.diffuse_reflectance(
        wl, geometry="sce", method="multipole", **skin2
    )
    np.testing.assert_allclose(d2, 2 * d, rtol=1e-12)
    assert d[0] / 0.3 == pytest.approx(0.0278, rel=0.3)


@pytest.mark.parametrize(
    "method,extra,kwargs",
    [
        ("multipole", [], {}),
        ("exact", ["--shape", "monte-carlo", "--escapes", "300"], {"shape": "monte-carlo", "escapes": 300}),
    ],
)
def test_profile_matches_skin_profile(cli, method, extra, kwargs):
    out, _ = cli("profile", *FLAGS, "--lambda", "560", "--method", method, *extra)
    _, rows = _rows(out)
    r_mm, printed = rows[:, 0], rows[:, 1]
    got = ss.profile(r_mm, 560.0, method=method, **kwargs, **SKIN)
    assert got.shape == r_mm.shape == (256,)
    # 7 significant digits printed for r and R(r): R's own rounding, plus the rounding of r times
    # the steepest neighbouring segment of the piecewise-linear table (the Monte Carlo shape is
    # jagged, so this term is the larger one there).
    slope = np.abs(np.diff(printed) / np.diff(r_mm))
    steepest = np.maximum(np.r_[slope[:1], slope], np.r_[slope, slope[-1:]])
    tol = 5e-7 * np.abs(printed) + steepest * 5e-7 * r_mm + 1e-12
    excess = np.abs(got - printed) - tol
    assert np.all(excess <= 0), f"worst excess {excess.max():.3g} at r = {r_mm[excess.argmax()]}"


def _write_spectrum(path, wl, r):
    path.write_text("lambda_nm,reflectance\n" + "".join(f"{a:g},{b:.6f}\n" for a, b in zip(wl, r)))


def test_fit_spectrum_matches_skin_fit(cli, tmp_path):
    wl = np.arange(400.0, 701.0, 20.0)
    # A measured-looking spectrum that is not the model's own: the model plus a slow ripple.
    truth = ss.diffuse_reflectance(wl, method="multipole", melanin=0.08, eumelanin=0.8, hemoglobin=0.04)
    measured = np.array([float(f"{v:.6f}") for v in truth * (1 + 0.03 * np.sin(wl / 37.0))])
    path = tmp_path / "s.csv"
    _write_spectrum(path, wl, measured)
    out, _ = cli("fit", "--spectrum", str(path), "--method", "multipole", "--json")
    ref = json.loads(out)["parameters"]
    fit = ss.fit_spectrum(wl, measured, method="multipole")
    assert float(fit.melanin) == pytest.approx(ref["melanin"], rel=1e-9, abs=1e-12)
    assert float(fit.eumelanin) == pytest.approx(ref["eumelanin_blend"], rel=1e-9, abs=1e-12)
    assert float(fit.hemoglobin) == pytest.approx(ref["hemoglobin"], rel=1e-9, abs=1e-12)


def test_fit_colour_matches_skin_fit(cli):
    # A colour inside the multipole model's gamut: a skin's own, rounded to 8-bit sRGB.
    wl = np.arange(400.0, 701.0, 10.0)
    hex_ = ss.srgb(ss.lab(wl, ss.diffuse_reflectance(wl, method="multipole", melanin=0.06, hemoglobin=0.02)))
    out, _ = cli("fit", "--srgb", hex_, "--method", "multipole", "--json")
    ref = json.loads(out)
    fit = ss.fit_colour(hex_, method="multipole")
    assert float(fit.melanin) == pytest.approx(ref["parameters"]["melanin"], rel=1e-9, abs=1e-12)
    assert float(fit.eumelanin) == pytest.approx(ref["parameters"]["eumelanin_blend"], rel=1e-9, abs=1e-12)
    assert float(fit.hemoglobin) == pytest.approx(ref["parameters"]["hemoglobin"], rel=1e-9, abs=1e-12)
    assert float(fit.delta_e_2000) == pytest.approx(ref["residual"]["delta_e_2000"], rel=1e-9)
    lab = ref["fitted"]["lab"]
    np.testing.assert_allclose(fit.lab, [lab["l"], lab["a"], lab["b"]], rtol=1e-9)
    # The same colour given as CIELAB (the CLI's --lab takes L,a,b).
    target = ss.lab(srgb=hex_)
    t = ref["target"]["lab"]
    np.testing.assert_allclose(target, [t["l"], t["a"], t["b"]], rtol=1e-12)


def test_export_matches_skin_export(cli):
    args = ["--escapes", "200", "--from", "450", "--to", "650", "--step", "100"]
    out, _ = cli("export", "mcml", *FLAGS, *args)
    text = ss.export("mcml", escapes=200, from_nm=450, to_nm=650, step_nm=100, **SKIN)
    assert text == out


def test_presets_match_skin_presets(cli):
    out, _ = cli("presets", "--json")
    ref = json.loads(out)
    got = ss.presets()
    assert [p["name"] for p in got] == [p["name"] for p in ref]
    for g, r in zip(got, ref):
        assert g["srgb"] == r["srgb"] and g["ita_category"] == r["ita_category"]
        assert g["lab"] == pytest.approx((r["lab"]["l"], r["lab"]["a"], r["lab"]["b"]), rel=1e-12)
        assert g["melanin"] == r["melanin"] and g["eumelanin"] == r["eumelanin_blend"]
        assert g["hemoglobin"] == r["hemoglobin"] and g["oil"] == r["oiliness"]
    # A preset's parameters are what `preset=` evaluates.
    dark = next(p for p in got if p["name"] == "dark")
    a = ss.diffuse_reflectance(550.0, preset="dark", method="multipole")
    b = ss.diffuse_reflectance(
        550.0, method="multipole", melanin=dark["melanin"], eumelanin=dark["eumelanin"],
        hemoglobin=dark["hemoglobin"], oil=dark["oil"],
    )
    assert a == b
