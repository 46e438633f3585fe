"""Batched fits: N spectra fitted together equal N single fits, on 1 and 2 threads alike."""

from __future__ import annotations

import numpy as np
import pytest

import spectral_skin as ss

WL = np.arange(400.0, 701.0, 20.0)


@pytest.fixture(scope="module")
def spectra() -> np.ndarray:
    mel = np.array([0.02, 0.1, 0.25])
    r = ss.diffuse_reflectance(WL, method="multipole", melanin=mel, eumelanin=0.75, hemoglobin=0.03)
    ripple = 1 + 0.02 * np.sin(WL / 29.0 + np.arange(3)[:, None])
    return r * ripple


def _same(a: ss.SpectrumFit, b: ss.SpectrumFit) -> None:
    for field in ("melanin", "eumelanin", "hemoglobin", "rms", "model"):
        np.testing.assert_array_equal(getattr(a, field), getattr(b, field))


def test_batch_equals_single_fits_and_threads_do_not_matter(spectra):
    one = ss.fit_spectrum(WL, spectra, method="multipole", threads=1)
    two = ss.fit_spectrum(WL, spectra, method="multipole", threads=2)
    _same(one, two)
    assert one.melanin.shape == (3,) and one.model.shape == spectra.shape
    for i in range(3):
        single = ss.fit_spectrum(WL, spectra[i], method="multipole")
        assert single.melanin.shape == ()
        assert float(single.melanin) == one.melanin[i]
        assert float(single.hemoglobin) == one.hemoglobin[i]
        np.testing.assert_array_equal(single.model, one.model[i])


def test_fit_recovers_the_skin_of_a_model_spectrum():
    truth = dict(melanin=0.07, eumelanin=0.6, hemoglobin=0.025)
    r = ss.diffuse_reflectance(WL, method="multipole", **truth)
    fit = ss.fit_spectrum(WL, r, method="multipole")
    assert float(fit.melanin) == pytest.approx(truth["melanin"], rel=1e-3)
    assert float(fit.hemoglobin) == pytest.approx(truth["hemoglobin"], rel=1e-3)
    assert float(fit.rms) < 1e-4


def test_weights_broadcast_and_a_zero_weight_ignores_a_point(spectra):
    bad = spectra[0].copy()
    bad[3] = 0.9  # an outlier
    w = np.ones(len(WL))
    w[3] = 0.0
    clean = ss.fit_spectrum(WL, spectra[0], method="multipole")
    masked = ss.fit_spectrum(WL, bad, w, method="multipole")
    assert float(masked.melanin) == pytest.approx(float(clean.melanin), rel=0.02)
    batch = ss.fit_spectrum(WL, spectra[:2], w, method="multipole")
    assert batch.melanin.shape == (2,)


def test_colour_fit_batches_and_reaches_its_target():
    target = ss.lab(srgb=["#c08a70", "#e0b8a0"])
    fits = ss.fit_colour(lab=target, method="multipole", threads=2)
    assert fits.melanin.shape == (2,) and fits.lab.shape == (2, 3)
    single = ss.fit_colour(lab=target[1], method="multipole", threads=1)
    assert float(single.melanin) == fits.melanin[1]
    # The fitted skin's own colour, recomputed through the spectrum, is the one reported.
    wl = np.arange(400.0, 701.0, 10.0)
    r = ss.diffuse_reflectance(
        wl, method="multipole", melanin=fits.melanin, eumelanin=fits.eumelanin, hemoglobin=fits.hemoglobin
    )
    np.testing.assert_allclose(ss.lab(wl, r), fits.lab, atol=1e-6)
    np.testing.assert_allclose(ss.delta_e_2000(fits.lab, target), fits.delta_e_2000, atol=1e-9)
