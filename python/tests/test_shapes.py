"""Broadcasting (scalar, (N,), (N, M)), wavelength on the last axis, and accepted dtypes."""

from __future__ import annotations

import numpy as np

import spectral_skin as ss

WL = np.array([420.0, 500.0, 580.0, 660.0])
MEL = np.array([0.01, 0.1, 0.3])


def _one(nm, m, method="multipole"):
    return float(ss.diffuse_reflectance(float(nm), melanin=float(m), method=method))


def test_scalar_in_scalar_out():
    r = ss.diffuse_reflectance(550.0, method="multipole")
    assert isinstance(r, np.ndarray) and r.shape == () and r.dtype == np.float64


def test_params_n_with_wavelengths_m_give_n_by_m():
    r = ss.diffuse_reflectance(WL, melanin=MEL, method="multipole")
    assert r.shape == (3, 4) and r.dtype == np.float64
    for i, m in enumerate(MEL):
        for j, nm in enumerate(WL):
            assert r[i, j] == _one(nm, m)


def test_params_n_with_wavelengths_n_by_m_pair_rows():
    wl = np.stack([WL, WL + 5, WL + 10])
    r = ss.diffuse_reflectance(wl, melanin=MEL, method="multipole")
    assert r.shape == (3, 4)
    for i in range(3):
        for j in range(4):
            assert r[i, j] == _one(wl[i, j], MEL[i])


def test_params_n_by_1_broadcast_against_params_m():
    c = ss.coefficients(500.0, melanin=MEL[:, None], hemoglobin=[0.01, 0.02])
    assert c.sigma_a_dermis_per_mm.shape == (3, 2)
    ref = ss.coefficients(500.0, melanin=0.1, hemoglobin=0.02)
    assert c.sigma_a_epidermis_per_mm[1, 1] == ref.sigma_a_epidermis_per_mm
    assert c.sigma_a_dermis_per_mm[1, 1] == ref.sigma_a_dermis_per_mm
    # σs' does not depend on the chromophores.
    assert np.all(c.sigma_s_reduced_per_mm == ref.sigma_s_reduced_per_mm)


def test_scalar_params_with_n_by_m_wavelengths():
    wl = WL.reshape(2, 2)
    c = ss.coefficients(wl, melanin=0.2)
    assert c.sigma_a_epidermis_per_mm.shape == (2, 2)
    flat = ss.coefficients(WL, melanin=0.2)
    np.testing.assert_array_equal(c.sigma_a_epidermis_per_mm.reshape(-1), flat.sigma_a_epidermis_per_mm)


def test_ints_float32_and_non_contiguous_inputs():
    ref = ss.diffuse_reflectance(WL, melanin=MEL, method="multipole")
    wl_int = WL.astype(np.int64)
    assert np.array_equal(ss.diffuse_reflectance(wl_int, melanin=MEL, method="multipole"), ref)
    mel32 = MEL.astype(np.float32)
    got = ss.diffuse_reflectance(WL, melanin=mel32, method="multipole")
    ref32 = ss.diffuse_reflectance(WL, melanin=mel32.astype(np.float64), method="multipole")
    assert got.dtype == np.float64 and np.array_equal(got, ref32)
    wide = np.zeros(2 * len(WL))
    wide[::2] = WL
    strided = wide[::2]
    assert not strided.flags["C_CONTIGUOUS"]
    assert np.array_equal(ss.diffuse_reflectance(strided, melanin=MEL, method="multipole"), ref)
    # A transposed (Fortran-ordered) reflectance block to the colour functions.
    block = np.asfortranarray(np.tile(np.linspace(0.2, 0.6, 31), (3, 1)))
    wl31 = np.arange(400, 701, 10)
    np.testing.assert_array_equal(ss.xyz(wl31, block), ss.xyz(wl31, np.ascontiguousarray(block)))


def test_lists_and_python_scalars():
    a = ss.coefficients([500, 600], melanin=[0.1, 0.2])
    b = ss.coefficients(np.array([500.0, 600.0]), melanin=np.array([0.1, 0.2]))
    for x, y in zip(a, b):
        assert x.shape == (2, 2) and np.array_equal(x, y)


def test_profile_shape_is_wavelengths_then_radii():
    r = np.array([[0.1, 0.2, 0.4], [0.5, 0.7, 0.9]])
    p = ss.profile(r, [450.0, 650.0], method="multipole")
    assert p.shape == (2, 2, 3)
    np.testing.assert_array_equal(p[1], ss.profile(r, 650.0, method="multipole"))


def test_colour_functions_keep_leading_axes():
    wl = np.arange(400.0, 701.0, 10.0)
    r = ss.diffuse_reflectance(wl, melanin=MEL[:, None] * np.ones((1, 2)), method="multipole")
    assert r.shape == (3, 2, 31)
    lab = ss.lab(wl, r)
    assert lab.shape == (3, 2, 3) and ss.ita(lab).shape == (3, 2)
    assert ss.delta_e_2000(lab, lab[0]).shape == (3, 2)
    assert np.all(ss.delta_e_2000(lab, lab) == 0.0)
