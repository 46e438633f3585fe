"""Type stubs of the native module: flat arrays, one row per evaluation point.

Use the documented functions of :mod:`spectral_skin`; these are their building blocks.
"""

from typing import Any

import numpy as np
import numpy.typing as npt

_F = npt.NDArray[np.float64]
_In = npt.ArrayLike

class SkinError(ValueError):
    """Bad input: the message starts with the parameter's name and states its valid range."""

DEFAULT_SHAPE_ESCAPES: int
DEFAULT_EXPORT_PHOTONS: int
DEFAULT_EXPORT_VOLUME_PHOTONS: int
DEFAULT_EXPORT_ESCAPES: int

def skin_columns() -> list[str]:
    """The keyword of each column of a parameter row."""

def preset_row(name: str | None = None) -> list[float]:
    """The parameter row of a named skin (None: the paper's light skin)."""

def presets() -> list[dict[str, Any]]:
    """Every named skin with its colour and parameters."""

def coefficients(lambda_nm: _In, params: _In) -> _F:
    """(N,) nm and (N, 10) rows → (N, 3): σa epidermis, σa dermis, σs' (mm⁻¹)."""

def diffuse_reflectance(
    lambda_nm: _In, params: _In, method: str, geometry: str, threads: int | None = None
) -> _F:
    """(N,) nm and (N, 10) rows → (N,) diffuse reflectance per incident flux."""

def profile(
    r_mm: _In,
    lambda_nm: _In,
    params: _In,
    method: str,
    shape: str,
    escapes: int,
    threads: int | None = None,
    roughness: float | None = None,
) -> _F:
    """(R,) mm, (L,) nm and one row → (L, R) R(r) in mm⁻²; a roughness puts the oily lobe on the faces."""

def monte_carlo(
    lambda_nm: float,
    params: _In,
    photons: int,
    batches: int,
    seed: int,
    r_max_mm: float,
    bins: int,
    threads: int | None = None,
    roughness: float | None = None,
) -> dict[str, Any]:
    """Layered Monte Carlo of one skin: totals with standard errors and R(r); a roughness puts the oily lobe on the faces."""

def adding_doubling(slabs: _In, quadrature_points: int, threads: int | None = None) -> _F:
    """(N, 7) slab rows (σa, σs, g, n, d, n_above, n_below) → (N, 3) diffuse R, specular R, T."""

def fit_spectrum(
    lambda_nm: _In,
    reflectance: _In,
    weights: _In | None,
    method: str,
    geometry: str,
    model: str,
    noise: float,
    threads: int | None = None,
) -> dict[str, Any]:
    """(M,) nm and (N, M) spectra → params (N, 10), rms (N,), model (N, M), surface_reflectance (N,)."""

def fit_colour(lab: _In, method: str, step_nm: float, threads: int | None = None) -> dict[str, Any]:
    """(N, 3) CIELAB → params (N, 10), lab (N, 3), delta_e (N,), in_gamut list[bool]."""

def xyz(lambda_nm: _In, reflectance: _In) -> _F:
    """(M,) uniform nm grid and (N, M) spectra → (N, 3) XYZ under D65 (white Y = 1)."""

def lab_from_xyz(xyz: _In) -> _F:
    """(N, 3) XYZ → (N, 3) CIELAB (D65)."""

def lab_from_srgb(srgb: list[str]) -> _F:
    """'#RRGGBB' colours → (N, 3) CIELAB (D65)."""

def srgb_from_lab(lab: _In) -> list[str]:
    """(N, 3) CIELAB → '#RRGGBB' colours."""

def delta_e_2000(lab1: _In, lab2: _In) -> _F:
    """Paired (N, 3) CIELAB rows → (N,) CIEDE2000."""

def ita(lab: _In) -> _F:
    """(N, 3) CIELAB → (N,) ITA°, degrees."""

def export(
    format: str,
    params: _In,
    from_nm: float,
    to_nm: float,
    step_nm: float,
    escapes: int,
    photons: int,
    volume_photons: int,
    colour_space: str,
    mcx_lambda_nm: float,
) -> tuple[str, list[str]]:
    """The file text of a format for one skin, and its notes."""

def maps(
    texels: _In,
    width: int,
    mask: _In | None,
    eumelanin: float | None,
    eumelanin_regions: int | None,
    exposure: str,
    gains: tuple[float, float, float],
    model: str,
    parameters: list[str] | None,
    thin_epidermis: bool,
    thin_epidermis_mm: float | None,
    thin_hemoglobin_max: float | None,
    cache: bool,
    threads: int | None = None,
) -> dict[str, Any]:
    """(N, 3) linear Rec.709 albedo in rows of ``width`` texels and (N,) flags, with β_m given,
    fitted or per region of ``eumelanin_regions`` texels, exposure ``"gains"`` (``gains``),
    ``"auto"`` or ``"auto-rgb"``, model ``"seed"``/``"full"``/``"auto"`` over the extended
    ``parameters`` (None: all) → melanin, hemoglobin,
    delta_e (N,) float64 (and eumelanin_map with regions), in_gamut, fitted (N,) bool and a summary
    dict (β_m and its allowed range, counts, ΔE2000, exposure, regions, extended parameters)."""
