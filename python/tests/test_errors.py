"""Each bad input raises SkinError (a ValueError) naming the parameter and its range."""

from __future__ import annotations

import numpy as np
import pytest

import spectral_skin as ss

WL = np.arange(400.0, 701.0, 50.0)


def test_skin_error_is_a_value_error():
    assert issubclass(ss.SkinError, ValueError)


@pytest.mark.parametrize(
    "call,name,range_",
    [
        (lambda: ss.coefficients(500.0, melanin=1.5), "melanin", "[0, 1]"),
        (lambda: ss.coefficients(500.0, melanin=[0.1, np.nan]), "melanin", "[0, 1]"),
        (lambda: ss.coefficients(500.0, eumelanin=-0.1), "eumelanin", "[0, 1]"),
        (lambda: ss.coefficients(500.0, hemoglobin=2), "hemoglobin", "[0, 1]"),
        (lambda: ss.diffuse_reflectance(500.0, oil=7), "oil", "[0, 1]"),
        (lambda: ss.coefficients(500.0, oxygenation=1.1), "oxygenation", "[0, 1]"),
        (lambda: ss.coefficients(500.0, bilirubin_g_per_l=11), "bilirubin_g_per_l", "[0, 10]"),
        (lambda: ss.coefficients(100.0), "wavelength_nm", "[250, 1000]"),
        (lambda: ss.coefficients([500.0, 1e308]), "wavelength_nm", "[250, 1000]"),
        (lambda: ss.diffuse_reflectance(500.0, method="diffusion"), "method", "exact, multipole"),
        (lambda: ss.diffuse_reflectance(500.0, geometry="d45"), "geometry", "sce, sci"),
        (lambda: ss.diffuse_reflectance(500.0, threads=0), "threads", "[1, 1024]"),
        (lambda: ss.coefficients(500.0, melanins=0.1), "melanins", "valid: melanin"),
        (lambda: ss.coefficients(500.0, preset="purple"), "preset", ""),
        (lambda: ss.coefficients(500.0, melanin=[0.1, 0.2], hemoglobin=[0.1, 0.2, 0.3]), "melanin", "broadcast"),
        (lambda: ss.coefficients(np.ones((2, 3)) * 500, melanin=[0.1, 0.2, 0.3]), "wavelength_nm", "broadcast"),
        (lambda: ss.coefficients(500.0, melanin="a lot"), "melanin", "real"),
        (lambda: ss.profile([-1.0], 500.0), "r_mm", "[0, inf)"),
        (lambda: ss.profile([1.0], 500.0, melanin=[0.1, 0.2]), "melanin", "scalar"),
        (lambda: ss.profile([1.0], 500.0, shape="fast"), "shape", "table, monte-carlo"),
        (lambda: ss.monte_carlo(500.0, photons=0), "photons", "[1"),
        (lambda: ss.monte_carlo(500.0, batches=1), "batches", "[2"),
        (lambda: ss.monte_carlo(500.0, r_max_mm=-1.0), "r_max_mm", "(0, inf)"),
        (lambda: ss.monte_carlo([500.0, 600.0]), "wavelength_nm", "scalar"),
        (lambda: ss.fit_spectrum(WL, np.full(5, 0.3)), "reflectance", "7 wavelengths"),
        (lambda: ss.fit_spectrum(WL[:, None], np.full(7, 0.3)), "wavelength_nm", "one axis"),
        (lambda: ss.fit_spectrum(WL, np.full((2, 7), 1.5)), "reflectance", "[0, 1]"),
        (lambda: ss.fit_spectrum(WL - 100, np.full(7, 0.3)), "reflectance", "400"),
        (lambda: ss.fit_spectrum(WL, np.full(7, 0.3), np.ones(3)), "weights", "broadcast"),
        (lambda: ss.fit_spectrum(WL, np.full(7, 0.3), model="huge"), "model", "seed, full, auto"),
        (lambda: ss.fit_spectrum(WL, np.full(7, 0.3), noise=0.0), "noise", "(0, inf)"),
        (lambda: ss.fit_colour(), "srgb", "exactly one"),
        (lambda: ss.fit_colour("#12345"), "srgb", "#RRGGBB"),
        (lambda: ss.fit_colour(lab=[50.0, 10.0]), "lab", "3"),
        (lambda: ss.fit_colour(lab=[50.0, 10.0, 15.0], step_nm=0.0), "step_nm", ""),
        (lambda: ss.xyz([400.0, 410.0, 430.0], [0.1, 0.2, 0.3]), "wavelength_nm", "equal steps"),
        (lambda: ss.xyz(WL, np.full(7, np.inf)), "reflectance", "finite"),
        (lambda: ss.lab(), "reflectance", "exactly one"),
        (lambda: ss.delta_e_2000([50.0, 0.0, 0.0], [[1.0, 2.0, 3.0]] * 2 + [[0.0, 0.0]]), "lab2", "3"),
        (lambda: ss.ita([50.0, 1.0]), "lab", "3"),
        (lambda: ss.export("obj"), "format", ""),
        (lambda: ss.export("mcml", escapes=10), "export options", "[100, 1e9]"),
        (lambda: ss.export("mcml", colour_space="p3"), "colour_space", "lin_rec709"),
    ],
)
def test_bad_input_names_the_parameter(call, name, range_):
    with pytest.raises(ss.SkinError) as e:
        call()
    text = str(e.value)
    assert text.startswith(name), text
    assert range_ in text, text
