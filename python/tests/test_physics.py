"""Closed forms, published values and physical limits the bindings must reproduce."""

from __future__ import annotations

import math

import numpy as np
import pytest

import spectral_skin as ss

WL = np.arange(400.0, 701.0, 10.0)


def test_white_reflector_is_the_d65_white_point():
    # CIE 15: D65 white (2°) X = 0.95047, Y = 1, Z = 1.08883 (4-5 digits published).
    np.testing.assert_allclose(ss.xyz(WL, np.ones(31)), [0.95047, 1.0, 1.08883], atol=2e-5)
    np.testing.assert_allclose(ss.lab(WL, np.ones(31)), [100.0, 0.0, 0.0], atol=1e-3)
    # A grey reflector scales XYZ linearly.
    np.testing.assert_allclose(ss.xyz(WL, 0.25 * np.ones(31)), 0.25 * ss.xyz(WL, np.ones(31)), rtol=1e-12)


@pytest.mark.parametrize(
    "lab1,lab2,de",
    [
        # Sharma, Wu & Dalal (2005), test data pairs 1, 7, 17 and 25.
        ((50.0, 2.6772, -79.7751), (50.0, 0.0, -82.7485), 2.0425),
        ((50.0, 0.0, 0.0), (50.0, -1.0, 2.0), 2.3669),
        ((50.0, 2.5, 0.0), (73.0, 25.0, -18.0), 27.1492),
        ((60.2574, -34.0099, 36.2677), (60.4626, -34.1751, 39.4387), 1.2644),
    ],
)
def test_delta_e_2000_reproduces_sharmas_table(lab1, lab2, de):
    assert float(ss.delta_e_2000(lab1, lab2)) == pytest.approx(de, abs=5e-5)
    assert float(ss.delta_e_2000(lab2, lab1)) == pytest.approx(de, abs=5e-5)


def test_ita_is_the_arctangent_of_lightness_over_b():
    lab = np.array([[60.0, 10.0, 10.0], [30.0, 5.0, 20.0], [70.0, 8.0, 15.0]])
    want = [math.degrees(math.atan((l - 50) / b)) for l, _, b in lab]
    np.testing.assert_allclose(ss.ita(lab), want, atol=1e-12)


def test_srgb_round_trips_through_lab():
    for hex_ in ["#ffffff", "#c08a70", "#3b2219", "#000000"]:
        assert ss.srgb(ss.lab(srgb=hex_)) == hex_


def test_coefficients_are_linear_in_the_chromophores():
    # [DJ06] eq 1: σa of the epidermis is linear in C_m between the baseline (C_m = 0) and melanin.
    a = ss.coefficients(WL, melanin=0.0).sigma_a_epidermis_per_mm
    b = ss.coefficients(WL, melanin=0.2).sigma_a_epidermis_per_mm
    c = ss.coefficients(WL, melanin=0.1).sigma_a_epidermis_per_mm
    np.testing.assert_allclose(c, (a + b) / 2, rtol=1e-12)


def test_monte_carlo_agrees_with_adding_doubling():
    # Two exact transport methods for the same slab: the Monte Carlo's diffuse reflectance and the
    # adding-doubling observable agree within the Monte Carlo's noise (4σ) plus AD's quadrature
    # error (< 1e-3 at 24 points).
    skin = dict(melanin=0.1, eumelanin=0.7, hemoglobin=0.03)
    mc = ss.monte_carlo(560.0, photons=40_000, **skin)
    ad = float(ss.diffuse_reflectance(560.0, method="exact", **skin))
    assert abs(mc.diffuse_reflectance - ad) < 4 * mc.diffuse_reflectance_stderr + 1e-3
    assert 0 < mc.diffuse_reflectance_stderr < 0.01
    # Energy: everything is reflected (diffusely or specularly), transmitted or absorbed.
    total = mc.diffuse_reflectance + mc.specular_reflectance + mc.transmittance + mc.absorbed
    assert total == pytest.approx(1.0, abs=1e-6)
    # R(r) integrates to the reflectance inside the grid.
    edges = np.linspace(0.0, 10.0, len(mc.r_mm) + 1)
    area = np.pi * (edges[1:] ** 2 - edges[:-1] ** 2)
    inside = float(np.sum(mc.reflectance_per_mm2 * area))
    assert inside + mc.beyond_grid == pytest.approx(mc.diffuse_reflectance, rel=1e-9)


def test_oily_surface_agrees_between_monte_carlo_and_adding_doubling():
    # The oily lobe as the boundary (docs/physics.md §10.1) in both exact methods: the Monte Carlo's
    # diffuse reflectance per entering photon against the exact profile's total under the same
    # surface (4σ plus the quadrature's 1e-3), and both above the Fresnel faces' by more than that.
    skin = dict(melanin=0.05, eumelanin=0.7, hemoglobin=0.02)
    mc = ss.monte_carlo(650.0, photons=40_000, surface="oily", **skin)
    per_entering = mc.diffuse_reflectance / (1.0 - mc.specular_reflectance)
    r = np.linspace(0.0, 30.0, 30_001)
    total = {
        s: float(np.trapezoid(2 * np.pi * r * ss.profile(r, [650.0], surface=s, **skin)[0], r))
        for s in ("smooth", "oily")
    }
    tol = 4 * mc.diffuse_reflectance_stderr + 2e-3
    assert abs(per_entering - total["oily"]) < tol
    assert total["oily"] - total["smooth"] > tol
    with pytest.raises(ss.SkinError, match="surface"):
        ss.profile([1.0], [560.0], surface="rough", **skin)
    with pytest.raises(ss.SkinError, match="roughness"):
        ss.monte_carlo(560.0, photons=1_000, surface="oily", roughness=0.0, **skin)


def test_monte_carlo_does_not_depend_on_threads():
    a = ss.monte_carlo(600.0, photons=4_000, seed=7, threads=1, preset="medium")
    b = ss.monte_carlo(600.0, photons=4_000, seed=7, threads=2, preset="medium")
    assert a.diffuse_reflectance == b.diffuse_reflectance
    np.testing.assert_array_equal(a.reflectance_per_mm2, b.reflectance_per_mm2)
    c = ss.monte_carlo(600.0, photons=4_000, seed=8, threads=2, preset="medium")
    assert c.diffuse_reflectance != a.diffuse_reflectance


def test_exact_is_darker_than_diffusion_for_dark_skin():
    # docs/physics.md §9: diffusion overestimates the totals of dark skin two- to threefold at 450 nm.
    ex = float(ss.diffuse_reflectance(450.0, preset="dark", method="exact"))
    mp = float(ss.diffuse_reflectance(450.0, preset="dark", method="multipole"))
    assert 1.5 < mp / ex < 4.0


def test_adding_doubling_limits():
    # Index-matched, purely absorbing: Beer–Lambert, T = e^{−σa d}, nothing reflected.
    t = ss.adding_doubling([0.5, 2.0], 0.0, 0.9, 1.0, n=1.0)
    np.testing.assert_allclose(t.transmittance, np.exp(-np.array([0.5, 2.0])), rtol=1e-9)
    np.testing.assert_allclose(t.diffuse_reflectance, 0.0, atol=1e-12)
    # Index 1.4 in air: the specular term is Fresnel's F(0) = ((n − 1)/(n + 1))².
    slab = ss.adding_doubling(0.1, 1.0, 0.0, 1.0, n=1.4)
    assert float(slab.specular_reflectance) == pytest.approx((0.4 / 2.4) ** 2, rel=1e-9)
    # No absorption: all light comes out (R + T = 1); a semi-infinite layer transmits nothing.
    cons = ss.adding_doubling(0.0, [1.0, 10.0], [0.0, 0.9], 1.0, n=1.4)
    np.testing.assert_allclose(cons.diffuse_reflectance + cons.specular_reflectance + cons.transmittance, 1.0, atol=1e-6)
    semi = ss.adding_doubling(0.1, 10.0, 0.9, np.inf)
    assert float(semi.transmittance) == 0.0 and 0 < float(semi.diffuse_reflectance) < 1
