"""Chromophore maps of albedo textures: round trips on synthetic textures made by the package's own
forward model, out-of-gamut texels, masks and bad shapes."""

from __future__ import annotations

import numpy as np
import pytest

import spectral_skin as ss

WL = np.arange(400.0, 701.0, 10.0)  # the maps' colour grid: 400-700 nm every 10 nm
# CIE XYZ → linear Rec.709 (skin_optics::color::Xyz::to_linear_srgb).
TO_REC709 = np.array([[3.2406, -1.5372, -0.4986], [-0.9689, 1.8758, 0.0415], [0.0557, -0.2040, 1.0570]])


def albedo(melanin, hemoglobin, eumelanin) -> np.ndarray:
    """Linear Rec.709 diffuse albedo (..., 3) of skins, as skin_fit::maps defines a texel's colour:
    the exact model's SCE diffuse reflectance under D65, CIE 1931 2°, 400-700 nm every 10 nm."""
    r = ss.diffuse_reflectance(
        WL, method="exact", geometry="sce", melanin=melanin, eumelanin=eumelanin, hemoglobin=hemoglobin
    )
    return ss.xyz(WL, r) @ TO_REC709.T


@pytest.fixture(scope="module")
def texture():
    """A 8 × 10 texture: C_m 0.01-0.18 along x, C_h 0.005-0.06 along y (geometric), β_m 0.6.

    Under darker melanin (C_m ≳ 0.25) the blood barely changes the colour, so C_h is not
    identifiable from three colour numbers (skin-fit's maps tests check it only where it is)."""
    x = np.linspace(0.0, 1.0, 10)
    y = np.linspace(0.0, 1.0, 8)
    c_m = 0.01 * (0.18 / 0.01) ** x[None, :] * np.ones((8, 1))
    c_h = 0.005 * (0.06 / 0.005) ** y[:, None] * np.ones((1, 10))
    return c_m, c_h, 0.6, albedo(c_m, c_h, 0.6)


def test_round_trip_recovers_the_maps(texture):
    c_m, c_h, beta, rgb = texture
    m = ss.maps(rgb, eumelanin=beta)
    assert set(m) >= {"melanin", "eumelanin", "hemoglobin", "delta_e", "in_gamut", "summary"}
    for k in ("melanin", "eumelanin", "hemoglobin", "delta_e"):
        assert m[k].shape == c_m.shape and m[k].dtype == np.float64, k
    assert m["in_gamut"].shape == c_m.shape and m["in_gamut"].all()
    np.testing.assert_array_equal(m["eumelanin"], beta)
    np.testing.assert_allclose(m["melanin"], c_m, rtol=0.02)
    np.testing.assert_allclose(m["hemoglobin"], c_h, rtol=0.02)
    assert np.median(m["delta_e"]) < 0.05 and m["delta_e"].max() < 0.2
    s = m["summary"]
    assert s["eumelanin"] == beta and not s["eumelanin_fitted"]
    assert s["eumelanin_min"] == s["eumelanin_max"] == beta
    assert s["texels"] == s["fitted"] == s["in_gamut"] == c_m.size and s["invalid"] == 0
    assert s["max_delta_e"] == pytest.approx(m["delta_e"].max(), abs=1e-6)


def test_fitted_eumelanin_brackets_the_truth(texture):
    c_m, c_h, beta, rgb = texture
    m = ss.maps(rgb)
    s = m["summary"]
    assert s["eumelanin_fitted"]
    assert s["eumelanin_min"] <= beta <= s["eumelanin_max"], s
    assert s["eumelanin_max"] - s["eumelanin_min"] < 1.0, s
    assert s["eumelanin_tolerance_de"] > 0 and s["eumelanin_rms_de"] >= 0
    np.testing.assert_array_equal(m["eumelanin"], s["eumelanin"])
    assert s["median_delta_e"] < 0.5 and s["p95_delta_e"] <= 1.0, s


def test_dtypes_and_strides_do_not_matter(texture):
    _, _, beta, rgb = texture
    ref = ss.maps(rgb, eumelanin=beta, threads=1)
    f32 = ss.maps(rgb.astype(np.float32), eumelanin=beta, threads=2)
    transposed = np.ascontiguousarray(rgb.transpose(1, 0, 2)).transpose(1, 0, 2)  # non-contiguous view
    assert not transposed.flags.c_contiguous
    view = ss.maps(transposed, eumelanin=beta)
    for k in ("melanin", "hemoglobin", "delta_e", "in_gamut"):
        np.testing.assert_array_equal(ref[k], f32[k])  # texels are f32 inside
        np.testing.assert_array_equal(ref[k], view[k])
    ints = ss.maps(np.zeros((2, 3, 3), dtype=np.int64), eumelanin=beta)  # black: out of gamut
    assert ints["melanin"].shape == (2, 3) and not ints["in_gamut"].any()


def test_non_skin_texels_are_flagged_and_finite():
    skin = albedo(0.05, 0.02, 0.6)
    rgb = np.array(
        [[skin, [0.0, 1.0, 0.0], [0.0, 0.0, 0.0]], [[1.0, 1.0, 1.0], [np.nan, 0.2, 0.1], [-1.0, 0.2, 0.1]]]
    )
    m = ss.maps(rgb, eumelanin=0.6)
    assert m["in_gamut"][0, 0], m["delta_e"][0, 0]
    flagged = np.ones((2, 3), dtype=bool)
    flagged[0, 0] = False
    assert not m["in_gamut"][flagged].any()
    assert (m["delta_e"][flagged] > 1.0).all(), m["delta_e"]
    for k in ("melanin", "hemoglobin", "delta_e"):
        assert np.isfinite(m[k]).all(), k
    eps = 1e-6  # the maps are f32 inside
    assert ((0.0 <= m["melanin"]) & (m["melanin"] <= 0.5 + eps)).all()
    top = np.where(m["thin_epidermis"], 0.25, 0.1)  # each texel within its skin's C_h range
    assert ((0.001 - eps <= m["hemoglobin"]) & (m["hemoglobin"] <= top + eps)).all()
    assert m["summary"]["invalid"] == 2 and m["summary"]["in_gamut"] == 1


def test_mask_leaves_texels_unfitted(texture):
    _, _, beta, rgb = texture
    mask = np.zeros(rgb.shape[:2], dtype=bool)
    mask[:, :5] = True
    m = ss.maps(rgb, mask, eumelanin=beta)
    full = ss.maps(rgb, eumelanin=beta)
    np.testing.assert_array_equal(m["fitted"], mask)
    np.testing.assert_array_equal(m["melanin"][mask], full["melanin"][mask])
    assert not m["in_gamut"][~mask].any() and (m["delta_e"][~mask] == 0).all()
    np.testing.assert_allclose(m["melanin"][~mask], np.median(m["melanin"][mask]), rtol=0.2)
    assert m["summary"]["fitted"] == mask.sum()
    ints = ss.maps(rgb, mask.astype(int), eumelanin=beta)  # 0/1 flags accepted
    np.testing.assert_array_equal(ints["melanin"], m["melanin"])


@pytest.mark.parametrize(
    "call,name,text",
    [
        (lambda: ss.maps(np.full((4, 5, 3), 0.3), np.ones((5, 4), dtype=bool)), "mask", "(4, 5)"),
        (lambda: ss.maps(np.full((4, 5, 3), 0.3), np.ones(20, dtype=bool)), "mask", "(4, 5)"),
        (lambda: ss.maps(np.full((4, 5, 4), 0.3)), "albedo_rgb", "(H, W, 3)"),
        (lambda: ss.maps(np.full((20, 3), 0.3)), "albedo_rgb", "(H, W, 3)"),
        (lambda: ss.maps(np.full((2, 2, 3), 0.3), eumelanin=1.5), "eumelanin", "[0, 1]"),
        (lambda: ss.maps(np.full((2, 2, 3), 0.3), eumelanin=np.nan), "eumelanin", "[0, 1]"),
        (lambda: ss.maps([["a", "b", "c"]]), "albedo_rgb", "real"),
        (lambda: ss.maps(np.full((2, 2, 3), 0.3), threads=0), "threads", "[1, 1024]"),
        (lambda: ss.maps(np.full((2, 2, 3), 0.3), exposure=3.0), "exposure", "[0.125, 2]"),
        (lambda: ss.maps(np.full((2, 2, 3), 0.3), exposure=(1.0, 0.5)), "exposure", "[0.125, 2]"),
        (lambda: ss.maps(np.full((2, 2, 3), 0.3), exposure="bright"), "exposure", "auto-rgb"),
        (lambda: ss.maps(np.full((2, 2, 3), 0.3), eumelanin_regions=2), "eumelanin_regions", "[4, 4096]"),
        (lambda: ss.maps(np.full((2, 2, 3), 0.3), eumelanin_regions=4.5), "eumelanin_regions", "[4, 4096]"),
        (
            lambda: ss.maps(np.full((2, 2, 3), 0.3), eumelanin=0.5, eumelanin_regions=8),
            "eumelanin_regions",
            "not both",
        ),
        (lambda: ss.maps(np.full((2, 2, 3), 0.3), model="best"), "model", "seed"),
        (lambda: ss.maps(np.full((2, 2, 3), 0.3), thin_epidermis_mm=0.5), "thin_epidermis_mm", "[0.04, 0.3]"),
        (lambda: ss.maps(np.full((2, 2, 3), 0.3), thin_hemoglobin_max=1.5), "thin_hemoglobin_max", "(0.001, 1]"),
        (lambda: ss.maps(np.full((2, 2, 3), 0.3), model="full", parameters=["gloss"]), "parameters", "mie_scale"),
    ],
)
def test_bad_input_names_the_parameter(call, name, text):
    with pytest.raises(ss.SkinError) as e:
        call()
    assert str(e.value).startswith(name), str(e.value)
    assert text in str(e.value), str(e.value)


def test_exposure_given_and_fitted(texture):
    """A texture photographed at gain 0.7 on every channel: the given gain 0.7 undoes it exactly
    (the same maps as the texture itself, to the f32 texels' rounding), and `auto` finds it within
    2 % (eighth-stop candidates and a parabola; the Rust test pins 1 % on a larger texture)."""
    c_m, _, beta, rgb = texture
    truth = ss.maps(rgb, eumelanin=beta)
    given = ss.maps(rgb * 0.7, eumelanin=beta, exposure=1 / 0.7)
    np.testing.assert_allclose(given["melanin"], truth["melanin"], rtol=1e-3)
    assert given["summary"]["exposure"] == pytest.approx([1 / 0.7] * 3)
    assert given["summary"]["exposure_range"] is None and given["in_gamut"].all()
    fitted = ss.maps(rgb * 0.7, eumelanin=beta, exposure="auto")
    g = fitted["summary"]["exposure"]
    assert g[0] == g[1] == g[2] and g[0] == pytest.approx(1 / 0.7, rel=0.02), g
    r = fitted["summary"]["exposure_range"]
    assert r["min"] <= g[0] <= r["max"] and r["tolerance_de"] > 0, r
    np.testing.assert_allclose(fitted["melanin"], c_m, rtol=0.05)
    balanced = ss.maps(rgb * np.array([0.7, 0.8, 0.9]), eumelanin=beta, exposure="auto-rgb")
    np.testing.assert_allclose(balanced["summary"]["exposure"], 1 / np.array([0.7, 0.8, 0.9]), rtol=0.03)
    assert balanced["summary"]["exposure_range"] is None


def test_eumelanin_per_region_follows_the_texture():
    """Halves of β_m 0.3 and 0.9 (C_m and C_h varying within each): 8 × 8 regions take β_m within
    0.2 of their half's (three colour numbers pin β_m only to about ±0.1-0.15 over 64 texels, the
    allowed widths of docs/physics.md §18; one candidate step is 0.05), and the eumelanin array
    holds each texel's region's value."""
    x = np.linspace(0.0, 1.0, 16)
    c_m = np.tile(0.01 * (0.12 / 0.01) ** x, (8, 1))
    c_h = np.tile(0.005 * (0.05 / 0.005) ** np.linspace(0.0, 1.0, 8)[:, None], (1, 16))
    beta = np.where(np.arange(16)[None, :] < 8, 0.3, 0.9) * np.ones((8, 1))
    rgb = albedo(c_m, c_h, beta)
    m = ss.maps(rgb, eumelanin_regions=8)
    left, right = m["eumelanin"][:, :8], m["eumelanin"][:, 8:]
    assert (left == left[0, 0]).all() and (right == right[0, 0]).all()
    assert abs(left[0, 0] - 0.3) <= 0.2 and abs(right[0, 0] - 0.9) <= 0.2, (left[0, 0], right[0, 0])
    r = m["summary"]["regions"]
    assert r["block"] == 8 and r["regions"] == 2
    assert r["min"] == pytest.approx(left[0, 0]) and r["max"] == pytest.approx(right[0, 0])
    assert m["summary"]["median_delta_e"] < 1.0


def test_model_fits_an_extended_parameter_per_texture(texture):
    """A texture whose skins all have a Mie scale of 1.5: `full` over that parameter returns it
    within 5 % (candidates 0.375 apart, a parabola between them; the Rust test pins the same) and
    the maps then reproduce the texture; `auto` over bilirubin, absent from the texture, keeps
    nothing."""
    c_m, c_h, beta, _ = texture
    r = ss.diffuse_reflectance(
        WL, method="exact", geometry="sce", melanin=c_m, eumelanin=beta, hemoglobin=c_h, mie_scale=1.5
    )
    rgb = ss.xyz(WL, r) @ TO_REC709.T
    seed = ss.maps(rgb, eumelanin=beta)
    assert seed["summary"]["model"] == "seed" and seed["summary"]["extended"] is None
    m = ss.maps(rgb, eumelanin=beta, model="full", parameters=["mie_scale"])
    e = m["summary"]["extended"]
    v = e["values"]["mie_scale"]
    assert v["kept"] and v["value"] == pytest.approx(1.5, rel=0.05), e
    assert v["range"]["min"] <= 1.5 <= v["range"]["max"], e
    assert e["rms_de"] < 0.25 * e["seed_rms_de"], e
    assert m["summary"]["median_delta_e"] < seed["summary"]["median_delta_e"]
    plain = ss.maps(albedo(c_m, c_h, beta), eumelanin=beta, model="auto", parameters="bilirubin_g_per_l")
    assert list(plain["summary"]["extended"]["values"]) == ["bilirubin_g_per_l"]
    assert not plain["summary"]["extended"]["values"]["bilirubin_g_per_l"]["kept"]


def test_thin_epidermis_reaches_lip_red():
    """Lip-like texels made under a 0.05 mm epidermis (C_m 0.02, C_h 0.06-0.18) beside skin of the
    default epidermis: with one skin the lips are out of gamut; with the thin-epidermis skin
    (default, C_h up to 0.25) they come in, flagged, with C_m within 5 % and C_h within 10 % (the
    Rust test's tolerances), and the default-epidermis texel keeps its skin. With that skin's C_h
    capped at 0.1 the texel of C_h 0.18 stays out."""
    c_h = np.array([[0.06, 0.09, 0.18]])
    r = ss.diffuse_reflectance(
        WL, method="exact", geometry="sce", melanin=0.02, eumelanin=0.6, hemoglobin=c_h, epidermis_thickness_mm=0.05
    )
    lips = ss.xyz(WL, r) @ TO_REC709.T
    rgb = np.concatenate([lips, albedo(0.05, 0.02, 0.6)[None, None, :]], axis=1)
    one = ss.maps(rgb, eumelanin=0.6, thin_epidermis=False)
    assert (one["delta_e"][0, :3] > 1.0).all() and not one["thin_epidermis"].any(), one["delta_e"]
    m = ss.maps(rgb, eumelanin=0.6)
    np.testing.assert_array_equal(m["thin_epidermis"][0], [True, True, True, False])
    assert m["in_gamut"].all(), m["delta_e"]
    np.testing.assert_allclose(m["melanin"][0, :3], 0.02, rtol=0.05)
    np.testing.assert_allclose(m["hemoglobin"][0, :3], c_h[0], rtol=0.1)
    assert m["summary"]["thin_epidermis"] == 3
    thicker = ss.maps(rgb, eumelanin=0.6, thin_epidermis_mm=0.3)
    assert not thicker["in_gamut"][0, :3].any()
    capped = ss.maps(rgb, eumelanin=0.6, thin_hemoglobin_max=0.1)
    assert capped["in_gamut"][0, :2].all() and not capped["in_gamut"][0, 2], capped["delta_e"]
