"""Donner & Jensen's spectral skin model over numpy arrays, computed in Rust.

Conventions, everywhere:

* wavelength in nm (valid range [250, 1000] nm; the data cover 400-700 nm best), on the last axis;
* absorption and reduced scattering coefficients in mm⁻¹, lengths and radii in mm, profiles R(r)
  in mm⁻²; reflectances are fractions in [0, 1];
* skin parameters are keyword arguments that broadcast against each other (scalars or arrays);
  a wavelength array adds a trailing axis: parameters of shape (N,) with wavelengths of shape (M,)
  give (N, M), and so do parameters of shape (N,) with wavelengths of shape (N, M);
* outputs are float64 arrays; bad input raises :class:`SkinError` (a ``ValueError``) whose message
  starts with the parameter's name and states its valid range;
* long calls release the GIL and run on all cores (``threads=`` limits them).

Skin parameters (defaults: the paper's light skin, or the ``preset=`` named skin):

========================== =========================================================== =========
keyword                    meaning                                                     range
========================== =========================================================== =========
``melanin``                melanin volume fraction C_m of the epidermis                [0, 1]
``eumelanin``              eumelanin share β_m of the melanin                          [0, 1]
``hemoglobin``             blood volume fraction C_h of the dermis                     [0, 1]
``oil``                    oiliness ρ_s, scale of the surface reflection lobe          [0, 1]
``oxygenation``            blood oxygen saturation γ                                   [0, 1]
``epidermis_thickness_mm`` epidermis thickness, mm                                     (0, 10]
``epidermis_blood``        blood volume fraction in the epidermis layer                [0, 1]
``bilirubin_g_per_l``      dermal bilirubin, g/L                                       [0, 10]
``mie_scale``              scale of the Mie term of σs'                                (0, 10]
``rayleigh_scale``         scale of the Rayleigh term of σs'                           (0, 10]
========================== =========================================================== =========

Example:
    >>> import numpy as np, spectral_skin as ss
    >>> wl = np.arange(400.0, 701.0, 10.0)
    >>> r = ss.diffuse_reflectance(wl, melanin=[0.01, 0.1, 0.3], method="multipole")
    >>> r.shape
    (3, 31)
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from typing import Any, Literal, NamedTuple, Sequence

import numpy as np
import numpy.typing as npt

from . import _native
from ._native import SkinError

__all__ = [
    "SkinError",
    "SKIN_PARAMETERS",
    "DEFAULT_ROUGHNESS",
    "Coefficients",
    "MonteCarloResult",
    "SpectrumFit",
    "ColourFit",
    "coefficients",
    "diffuse_reflectance",
    "profile",
    "monte_carlo",
    "SlabTotals",
    "adding_doubling",
    "fit_spectrum",
    "fit_colour",
    "export",
    "maps",
    "xyz",
    "lab",
    "srgb",
    "delta_e_2000",
    "ita",
    "presets",
]

_log = logging.getLogger(__name__)

#: The skin-parameter keywords, in the order of a parameter row.
SKIN_PARAMETERS: tuple[str, ...] = tuple(_native.skin_columns())

Method = Literal["exact", "multipole"]
Geometry = Literal["sce", "sci"]
Surface = Literal["smooth", "oily"]

#: The oily surface's default Beckmann RMS slope m (the renderer's, [DJ06]).
DEFAULT_ROUGHNESS: float = 0.3
ArrayLike = npt.ArrayLike
Array = npt.NDArray[np.float64]


def _real(x: Any, name: str) -> Array:
    """``x`` as a float64 array (ints, float32 and any strides accepted); names ``name`` if not real."""
    try:
        a = np.asarray(x)
        if a.dtype.kind not in "biuf":
            raise TypeError(f"dtype {a.dtype}")
        return a.astype(np.float64, copy=False)
    except (TypeError, ValueError) as e:
        raise SkinError(f"{name}: not an array of real numbers ({e})") from None


def _skin(preset: str | None, skin: dict[str, Any]) -> tuple[list[Array], tuple[int, ...]]:
    """The parameter arrays (one per :data:`SKIN_PARAMETERS`) and their broadcast shape."""
    unknown = sorted(set(skin) - set(SKIN_PARAMETERS))
    if unknown:
        raise SkinError(
            f"{unknown[0]}: unknown skin parameter (valid: {', '.join(SKIN_PARAMETERS)})"
        )
    base = _native.preset_row(preset)
    arrays = [
        _real(skin[k], k) if k in skin else np.asarray(base[i], dtype=np.float64)
        for i, k in enumerate(SKIN_PARAMETERS)
    ]
    try:
        shape = np.broadcast_shapes(*(a.shape for a in arrays))
    except ValueError:
        shapes = ", ".join(f"{k} {np.shape(skin[k])}" for k in skin)
        raise SkinError(f"{', '.join(skin)}: shapes do not broadcast ({shapes})") from None
    return arrays, shape


def _points(
    wavelength_nm: ArrayLike, preset: str | None, skin: dict[str, Any]
) -> tuple[Array, Array, tuple[int, ...]]:
    """Flat wavelengths, parameter rows (N × 10) and the output shape of a spectral call."""
    lam = _real(wavelength_nm, "wavelength_nm")
    arrays, pshape = _skin(preset, skin)
    if lam.ndim == 0:
        shape = pshape
        params = [np.broadcast_to(a, shape) for a in arrays]
    else:
        try:
            shape = np.broadcast_shapes(pshape + (1,), lam.shape)
        except ValueError:
            raise SkinError(
                f"wavelength_nm: shape {lam.shape} does not broadcast with the skin parameters' "
                f"{pshape} plus a trailing wavelength axis"
            ) from None
        params = [np.broadcast_to(np.broadcast_to(a, pshape)[..., None], shape) for a in arrays]
    rows = np.stack([p.reshape(-1) for p in params], axis=-1)
    return np.broadcast_to(lam, shape).reshape(-1), rows, shape


def _roughness(surface: str, roughness: float) -> float | None:
    """The native call's surface: ``None`` for Fresnel faces, the lobe's slope for the oily one."""
    if surface == "smooth":
        return None
    if surface != "oily":
        raise SkinError(f"surface: '{surface}' is not one of smooth, oily")
    return float(roughness)


def _one_skin(preset: str | None, skin: dict[str, Any]) -> Array:
    """The parameter row of one skin: every parameter must be a scalar."""
    arrays, shape = _skin(preset, skin)
    if shape != ():
        k = next(k for k in skin if np.shape(skin[k]) != ())
        raise SkinError(f"{k}: must be a scalar here (one skin per call), got shape {np.shape(skin[k])}")
    return np.array([float(a) for a in arrays])


class Coefficients(NamedTuple):
    """Optical coefficients of the two-layer skin ([DJ06] eqs 1-6), each of the call's shape."""

    sigma_a_epidermis_per_mm: Array
    """Absorption coefficient σa of the epidermis, mm⁻¹."""
    sigma_a_dermis_per_mm: Array
    """Absorption coefficient σa of the dermis, mm⁻¹."""
    sigma_s_reduced_per_mm: Array
    """Reduced scattering coefficient σs' (epidermis; the dermis's at the default scale), mm⁻¹."""


def coefficients(wavelength_nm: ArrayLike, *, preset: str | None = None, **skin: ArrayLike) -> Coefficients:
    """Absorption σa per layer and reduced scattering σs', mm⁻¹, at ``wavelength_nm`` (nm).

    Skin parameters (``melanin=``, ``eumelanin=``, ``hemoglobin=``, … see the module doc) broadcast;
    the result's arrays have the broadcast shape (a wavelength array adds the last axis).

    Example:
        >>> c = coefficients([450, 550, 650], melanin=0.1, eumelanin=0.7, hemoglobin=0.02)
        >>> c.sigma_a_epidermis_per_mm.shape
        (3,)
    """
    lam, rows, shape = _points(wavelength_nm, preset, skin)
    out = _native.coefficients(lam, rows)
    return Coefficients(*(out[:, i].reshape(shape) for i in range(3)))


def diffuse_reflectance(
    wavelength_nm: ArrayLike,
    *,
    preset: str | None = None,
    method: Method = "exact",
    geometry: Geometry = "sce",
    threads: int | None = None,
    **skin: ArrayLike,
) -> Array:
    """Diffuse reflectance per unit incident flux (fraction in [0, 1]) at ``wavelength_nm`` (nm).

    ``method="exact"`` (default): adding-doubling transport, right for every skin tone;
    ``"multipole"``: the paper's diffusion ([DJ05]), too bright for dark skin.
    ``geometry="sce"`` (default): a d/8 spectrophotometer with the specular component excluded,
    (1 − F_r(0)) R_d; ``"sci"`` adds the oily surface's reflection at 8°, ρ_s a(cos 8°).

    Example:
        >>> r = diffuse_reflectance(np.arange(400, 701, 10), melanin=[0.02, 0.2], method="multipole")
        >>> r.shape
        (2, 31)
    """
    lam, rows, shape = _points(wavelength_nm, preset, skin)
    out = _native.diffuse_reflectance(lam, rows, method, geometry, threads)
    return out.reshape(shape)


def profile(
    r_mm: ArrayLike,
    wavelength_nm: ArrayLike,
    *,
    preset: str | None = None,
    method: Method = "exact",
    shape: Literal["table", "monte-carlo"] = "table",
    escapes: int = _native.DEFAULT_SHAPE_ESCAPES,
    threads: int | None = None,
    surface: Surface = "smooth",
    roughness: float = DEFAULT_ROUGHNESS,
    **skin: float,
) -> Array:
    """Radial diffuse reflectance profile R(r), mm⁻² per unit flux entering, of one skin.

    ``r_mm``: radii in mm (≥ 0, any shape); ``wavelength_nm``: nm (any shape). The result has shape
    ``wavelength_nm.shape + r_mm.shape``. Skin parameters must be scalars (one skin per call).
    ``method="exact"`` scales the layered Monte Carlo's shape to the adding-doubling total; its shape
    comes from the cached universal table (``shape="table"``) or a Monte Carlo run per wavelength
    with ``escapes`` escaping photons (``shape="monte-carlo"``, noise ∝ 1/√escapes).
    ``surface="oily"`` computes the exact total under the oily lobe as the boundary (Beckmann slope
    ``roughness``, the skin's ``oil`` ρ_s; what the renderer's default surface does, docs/physics.md
    §10.1); ``"smooth"`` (default) under Fresnel faces, the model's. Diffusion ignores it.

    Example:
        >>> p = profile([0.1, 0.5, 1.0], [450, 650], melanin=0.05, method="multipole")
        >>> p.shape
        (2, 3)
    """
    r = _real(r_mm, "r_mm")
    lam = _real(wavelength_nm, "wavelength_nm")
    row = _one_skin(preset, skin)
    m = _roughness(surface, roughness)
    out = _native.profile(r.reshape(-1), lam.reshape(-1), row, method, shape, int(escapes), threads, m)
    return out.reshape(lam.shape + r.shape)


@dataclass(frozen=True)
class MonteCarloResult:
    """Totals (fractions of the incident photons) with standard errors over batches, and R(r)."""

    photons: int
    """Photons traced."""
    diffuse_reflectance: float
    """Diffuse reflectance, fraction of incident light (specular excluded)."""
    diffuse_reflectance_stderr: float
    """Standard error of :attr:`diffuse_reflectance`."""
    transmittance: float
    """Fraction transmitted through the bottom (0 for the semi-infinite dermis)."""
    transmittance_stderr: float
    """Standard error of :attr:`transmittance`."""
    absorbed: float
    """Fraction absorbed."""
    absorbed_stderr: float
    """Standard error of :attr:`absorbed`."""
    specular_reflectance: float
    """Specular reflection of the top surface, fraction."""
    r_mm: Array
    """Annulus mid radii, mm."""
    reflectance_per_mm2: Array
    """R(r) per annulus, mm⁻² per incident photon."""
    reflectance_stderr_per_mm2: Array
    """Standard error of R(r), mm⁻²."""
    beyond_grid: float
    """Diffuse reflectance escaping beyond the last annulus, fraction."""


def monte_carlo(
    wavelength_nm: float,
    *,
    preset: str | None = None,
    photons: int = 100_000,
    batches: int = 32,
    seed: int = 1,
    threads: int | None = None,
    r_max_mm: float = 10.0,
    bins: int = 1000,
    surface: Surface = "smooth",
    roughness: float = DEFAULT_ROUGHNESS,
    **skin: float,
) -> MonteCarloResult:
    """Layered Monte Carlo ([WJZ95]) of one skin at one wavelength (nm): totals and R(r).

    ``photons`` in [1, 1e12] split into ``batches`` in [2, 1e6] (for the standard errors);
    ``seed`` fixes the random streams, so the result does not depend on ``threads``. R(r) is tallied
    on ``bins`` equal annuli out to ``r_max_mm`` (mm). Skin parameters must be scalars. ``surface``
    and ``roughness`` as in :func:`profile`: ``"oily"`` reflects photons meeting the surface with the
    lobe's albedo, ``"smooth"`` with Fresnel's.

    Example:
        >>> mc = monte_carlo(550.0, melanin=0.05, photons=20_000)
        >>> 0 < mc.diffuse_reflectance < 1
        True
    """
    lam = _real(wavelength_nm, "wavelength_nm")
    if lam.ndim != 0:
        raise SkinError(f"wavelength_nm: must be a scalar here, got shape {lam.shape}")
    row = _one_skin(preset, skin)
    for name, v, lo in (("photons", photons, 1), ("batches", batches, 2), ("bins", bins, 1), ("seed", seed, 0)):
        if not isinstance(v, (int, np.integer)) or v < lo:
            raise SkinError(f"{name}: {v!r} outside [{lo}, …] (a whole number)")
    m = _roughness(surface, roughness)
    d = _native.monte_carlo(float(lam), row, int(photons), int(batches), int(seed), float(r_max_mm), int(bins), threads, m)
    return MonteCarloResult(**d)


class SlabTotals(NamedTuple):
    """Totals of a slab for a normally incident beam, fractions of the incident power."""

    diffuse_reflectance: Array
    """Diffuse reflectance (specular reflection of the top surface excluded)."""
    specular_reflectance: Array
    """Specular reflection of the top surface."""
    transmittance: Array
    """Total transmittance (0 for a semi-infinite layer)."""


def adding_doubling(
    sigma_a_per_mm: ArrayLike,
    sigma_s_per_mm: ArrayLike,
    g: ArrayLike,
    thickness_mm: ArrayLike,
    *,
    n: ArrayLike = 1.4,
    n_above: ArrayLike = 1.0,
    n_below: ArrayLike = 1.0,
    quadrature_points: int = 24,
    threads: int | None = None,
) -> SlabTotals:
    """Exact totals of a homogeneous slab by adding-doubling ([Prahl95], [vdH80]), broadcast.

    ``sigma_a_per_mm``, ``sigma_s_per_mm``: absorption and scattering coefficients, mm⁻¹ (σs, not σs');
    ``g``: Henyey-Greenstein anisotropy; ``thickness_mm``: mm (``np.inf``: semi-infinite);
    ``n``: the slab's index, ``n_above``/``n_below``: the media's (Fresnel boundaries);
    ``quadrature_points``: directions per hemisphere, even, in [4, 64].

    Example:
        >>> t = adding_doubling(0.1, 10.0, 0.9, [0.5, 1.0, np.inf])
        >>> t.transmittance.shape
        (3,)
    """
    names = ("sigma_a_per_mm", "sigma_s_per_mm", "g", "n", "thickness_mm", "n_above", "n_below")
    values = (sigma_a_per_mm, sigma_s_per_mm, g, n, thickness_mm, n_above, n_below)
    arrays = [_real(v, k) for k, v in zip(names, values)]
    try:
        shape = np.broadcast_shapes(*(a.shape for a in arrays))
    except ValueError:
        raise SkinError(f"{', '.join(names)}: shapes do not broadcast") from None
    slabs = np.stack([np.broadcast_to(a, shape).reshape(-1) for a in arrays], axis=-1)
    out = _native.adding_doubling(slabs, int(quadrature_points), threads)
    return SlabTotals(*(out[:, i].reshape(shape) for i in range(3)))


@dataclass(frozen=True)
class SpectrumFit:
    """Skin parameters fitted to spectra, each of the batch shape (the spectra's leading axes)."""

    melanin: Array
    """Melanin fraction C_m."""
    eumelanin: Array
    """Eumelanin blend β_m."""
    hemoglobin: Array
    """Hemoglobin fraction C_h."""
    oil: Array
    """Oiliness ρ_s (fitted under ``geometry="sci"``; else the default)."""
    oxygenation: Array
    """Blood oxygenation γ (the default unless fitted)."""
    epidermis_thickness_mm: Array
    """Epidermis thickness, mm (the default)."""
    epidermis_blood: Array
    """Epidermal blood fraction (fitted by ``model="full"|"auto"``; else 0)."""
    bilirubin_g_per_l: Array
    """Bilirubin, g/L (fitted by ``model="full"|"auto"``; else 0)."""
    mie_scale: Array
    """Mie scattering scale (fitted by ``model="full"|"auto"``; else 1)."""
    rayleigh_scale: Array
    """Rayleigh scattering scale (fitted by ``model="full"|"auto"``; else 1)."""
    rms: Array
    """Weighted RMS residual of the fit, reflectance units."""
    model: Array
    """The fitted model's spectrum on the input wavelengths (batch shape + (M,))."""
    surface_reflectance: Array
    """Surface reflection the instrument adds (0 for SCE), fraction."""


def fit_spectrum(
    wavelength_nm: ArrayLike,
    reflectance: ArrayLike,
    weights: ArrayLike | None = None,
    *,
    geometry: Geometry = "sce",
    model: Literal["seed", "full", "auto"] = "seed",
    method: Method = "exact",
    noise: float = 0.005,
    threads: int | None = None,
) -> SpectrumFit:
    """Fit skin parameters to measured reflectance spectra, one independent fit per spectrum.

    ``wavelength_nm``: (M,) nm, strictly increasing within [400, 700]; ``reflectance``: (..., M)
    fractions in [0, 1]; ``weights``: None, (M,) or (..., M), ≥ 0. ``geometry`` names the
    instrument (``"sce"``/``"sci"``), ``model`` the parameters fitted (``"seed"``: C_m, β_m, C_h;
    ``"full"``/``"auto"``: the extended physiology too, ``"auto"`` choosing by the data with
    measurement ``noise`` σ in reflectance units). The spectra run in parallel; the result does not
    depend on ``threads``.

    Example:
        >>> wl = np.arange(400.0, 701.0, 10.0)
        >>> fit = fit_spectrum(wl, diffuse_reflectance(wl, melanin=0.05), method="exact")
        >>> round(float(fit.melanin), 2)
        0.05
    """
    lam = _real(wavelength_nm, "wavelength_nm")
    if lam.ndim != 1:
        raise SkinError(f"wavelength_nm: must be one axis (M,), got shape {lam.shape}")
    r = _real(reflectance, "reflectance")
    if r.ndim == 0 or r.shape[-1] != lam.shape[0]:
        raise SkinError(f"reflectance: last axis must have the {lam.shape[0]} wavelengths, got shape {r.shape}")
    batch = r.shape[:-1]
    w = None
    if weights is not None:
        wa = _real(weights, "weights")
        try:
            w = np.broadcast_to(wa, r.shape).reshape(-1, lam.shape[0])
        except ValueError:
            raise SkinError(f"weights: shape {wa.shape} does not broadcast to reflectance's {r.shape}") from None
    d = _native.fit_spectrum(lam, r.reshape(-1, lam.shape[0]), w, method, geometry, model, float(noise), threads)
    params = d["params"]
    cols = {k: params[:, i].reshape(batch) for i, k in enumerate(SKIN_PARAMETERS)}
    return SpectrumFit(
        **cols,
        rms=d["rms"].reshape(batch),
        model=d["model"].reshape(r.shape),
        surface_reflectance=d["surface_reflectance"].reshape(batch),
    )


@dataclass(frozen=True)
class ColourFit:
    """Skin parameters fitted to colours, each of the batch shape."""

    melanin: Array
    """Melanin fraction C_m."""
    eumelanin: Array
    """Eumelanin blend β_m."""
    hemoglobin: Array
    """Hemoglobin fraction C_h."""
    lab: Array
    """CIELAB (D65) of the fitted skin, batch shape + (3,)."""
    delta_e_2000: Array
    """CIEDE2000 distance from the target."""
    in_gamut: npt.NDArray[np.bool_]
    """Whether some skin has the target colour (else the fit is the nearest skin)."""


def fit_colour(
    srgb: str | Sequence[str] | None = None,
    lab: ArrayLike | None = None,
    *,
    method: Method = "exact",
    step_nm: float = 10.0,
    threads: int | None = None,
) -> ColourFit:
    """Fit C_m, β_m, C_h to colours: ``srgb`` ``"#RRGGBB"`` string(s) or ``lab`` (..., 3) CIELAB (D65).

    The model's colour is its diffuse reflectance under D65 (CIE 1931 2°) on a ``step_nm`` grid
    (nm, (0, 100]) over 400-700 nm. Colours are fitted in parallel.

    Example:
        >>> fit = fit_colour(srgb=["#c7b3ab", "#8d5a45"])
        >>> fit.melanin.shape
        (2,)
    """
    if (srgb is None) == (lab is None):
        raise SkinError("srgb: give exactly one of srgb= or lab=")
    if srgb is not None:
        hexes = [srgb] if isinstance(srgb, str) else list(srgb)
        if not all(isinstance(h, str) for h in hexes):
            raise SkinError("srgb: expected '#RRGGBB' strings")
        target = _native.lab_from_srgb(hexes)
        batch: tuple[int, ...] = () if isinstance(srgb, str) else (len(hexes),)
    else:
        t = _real(lab, "lab")
        if t.ndim == 0 or t.shape[-1] != 3:
            raise SkinError(f"lab: last axis must hold the 3 values L*, a*, b*, got shape {t.shape}")
        batch = t.shape[:-1]
        target = t.reshape(-1, 3)
    d = _native.fit_colour(target, method, float(step_nm), threads)
    params = d["params"]
    return ColourFit(
        melanin=params[:, 0].reshape(batch),
        eumelanin=params[:, 1].reshape(batch),
        hemoglobin=params[:, 2].reshape(batch),
        lab=d["lab"].reshape(batch + (3,)),
        delta_e_2000=d["delta_e"].reshape(batch),
        in_gamut=np.asarray(d["in_gamut"], dtype=bool).reshape(batch),
    )


def export(
    format: Literal[
        "openpbr",
        "standard-surface",
        "unreal",
        "hdrp",
        "gaussians",
        "burley",
        "pbrt",
        "mitsuba",
        "mcml",
        "mcx",
        "blender",
        "blender-json",
    ],
    *,
    preset: str | None = None,
    from_nm: float = 400.0,
    to_nm: float = 700.0,
    step_nm: float = 10.0,
    escapes: int = _native.DEFAULT_EXPORT_ESCAPES,
    photons: int = _native.DEFAULT_EXPORT_PHOTONS,
    volume_photons: int = _native.DEFAULT_EXPORT_VOLUME_PHOTONS,
    colour_space: Literal["lin_rec709", "acescg"] = "lin_rec709",
    mcx_lambda_nm: float = 550.0,
    **skin: float,
) -> str:
    """The skin written for another renderer or simulator, as the file's text (what ``skin export`` writes).

    Each format's model is fitted to the exact profiles over ``from_nm``-``to_nm`` every ``step_nm``
    (nm); ``escapes`` sets the Monte Carlo shapes' accuracy, ``photons``/``volume_photons`` the
    volume fits'. The notes on what the file holds are logged at INFO on the ``spectral_skin`` logger.

    Example:
        >>> text = export("mcml", melanin=0.05, escapes=500)
        >>> text.splitlines()[0].startswith("#")
        True
    """
    row = _one_skin(preset, skin)
    for name, v in (("escapes", escapes), ("photons", photons), ("volume_photons", volume_photons)):
        if not isinstance(v, (int, np.integer)) or v < 0:
            raise SkinError(f"{name}: {v!r} is not a whole number ≥ 0")
    text, notes = _native.export(
        format, row, float(from_nm), float(to_nm), float(step_nm), int(escapes), int(photons),
        int(volume_photons), colour_space, float(mcx_lambda_nm),
    )
    for note in notes:
        _log.info("%s", note)
    return text


def maps(
    albedo_rgb: ArrayLike,
    mask: ArrayLike | None = None,
    *,
    eumelanin: float | None = None,
    eumelanin_regions: int | None = None,
    exposure: float | tuple[float, float, float] | str = 1.0,
    model: str = "seed",
    parameters: Sequence[str] | None = None,
    thin_epidermis: bool = True,
    thin_epidermis_mm: float | None = None,
    thin_hemoglobin_max: float | None = None,
    cache: bool = True,
    threads: int | None = None,
) -> dict[str, Any]:
    """Chromophore maps of an albedo texture: melanin C_m and blood C_h per texel, one β_m (``skin maps``).

    ``albedo_rgb``: (H, W, 3) linear Rec.709 (sRGB primaries, not gamma-encoded) diffuse albedo, a
    perfect white diffuser at 1: the skin's diffuse reflectance (specular excluded, SCE) under D65
    with the CIE 1931 2° observer, what :func:`diffuse_reflectance` and :func:`xyz` give through
    the XYZ → linear Rec.709 matrix. ``mask``: optional (H, W) flags (True: fit the texel); texels
    outside it are not fitted and get the median of the fitted maps, ΔE 0 and ``in_gamut`` False.
    ``eumelanin``: the texture's eumelanin blend β_m in [0, 1], or None to fit one β_m over the
    texels (or per region, below). ``eumelanin_regions``: a block size B in [4, 4096] to fit one
    β_m per square region of B × B texels with a smoothness prior between neighbours (``skin maps
    --eumelanin-regions B``; not with ``eumelanin``). ``exposure``: gains on the linear texels
    before the fit (``--exposure``): one gain for R = G = B, three (R, G, B), each in [0.125, 2],
    ``"auto"`` (one gain fitted with β_m) or ``"auto-rgb"`` (one per channel: exposure and white
    balance); residuals are measured at the texture's own exposure. ``model``: ``"seed"`` (C_m,
    β_m, C_h only), ``"full"`` (every parameter of :func:`fit`'s ``model="full"`` fitted once per
    texture, each costing a few CPU-seconds) or ``"auto"`` (each kept only where it lowers the
    residual). ``parameters``: the extended parameters ``model`` tries, by name
    (``epidermis_blood``, ``epidermis_thickness_mm``, ``oxygenation``, ``mie_scale``,
    ``rayleigh_scale``, ``dermis_scattering_scale``, ``bilirubin_g_per_l``; default all).
    ``thin_epidermis``: fit texels out of gamut again under a thin epidermis of
    ``thin_epidermis_mm`` (in [0.04, 0.3] mm; None: 0.05 mm, the lip vermilion's; ``skin maps
    --thin-epidermis``) and keep that skin where it reproduces the texel at least 1 ΔE2000 closer
    (docs/physics.md §18); that skin's C_h reaches ``thin_hemoglobin_max`` (in (0.001, 1]; None:
    0.25, ``--thin-hemoglobin-max``). ``cache``: keep the forward table (built once, a few CPU-seconds) in the disk cache
    (``$SKIN_CACHE_DIR``, else ``$XDG_CACHE_HOME/skin``, else ``~/.cache/skin``).

    Non-finite, negative or huge (> 16) components are replaced (NaN by 0, then clamped), fitted
    and flagged out of gamut. The work runs on all cores (``threads=`` limits them) with the GIL
    released.

    Returns a dict of (H, W) arrays:

    =================== ==================================================================
    ``melanin``         melanin volume fraction C_m, float64 in [0, 0.5]
    ``eumelanin``       eumelanin blend β_m (the same for every texel), float64 in [0, 1]
    ``hemoglobin``      hemoglobin volume fraction C_h, float64 in [0.001, 0.1]
    ``delta_e``         CIEDE2000 between the texel and the fitted skin, float64 (0 off the mask)
    ``in_gamut``        bool: fitted and reproduced within ΔE2000 ≤ 1
    ``fitted``          bool: inside the mask
    ``thin_epidermis``  bool: fitted under the thin epidermis (C_m, C_h are that skin's)
    =================== ==================================================================

    With ``eumelanin_regions`` the ``eumelanin`` array holds each texel's region's β_m (and the
    summary's ``eumelanin`` their median).

    and ``summary``, a dict: ``eumelanin`` (β_m), ``eumelanin_fitted`` (bool),
    ``eumelanin_min``/``eumelanin_max`` (the β_m range the texels allow: candidates whose RMS
    ΔE2000, capped at 3 per texel, is within ``eumelanin_tolerance_de`` of the best,
    ``eumelanin_rms_de``; both ends equal β_m and the two ΔE None when β_m was given),
    ``texels``, ``fitted``, ``in_gamut``, ``invalid`` (counts), ``median_delta_e``,
    ``p95_delta_e``, ``max_delta_e`` (over the fitted texels), ``in_gamut_delta_e`` (1.0),
    ``exposure`` (the R, G, B gains applied), ``exposure_range`` (for ``"auto"``: ``min``, ``max``,
    ``tolerance_de``, ``rms_de`` of the gains the texels allow; else None), ``regions`` (with
    ``eumelanin_regions``: ``block``, ``regions``, ``min``, ``median``, ``max`` β_m and
    ``median_allowed_width``; else None), ``model``, ``thin_epidermis`` (the count of such texels) and ``extended`` (for ``"full"``/``"auto"``:
    ``seed_rms_de``, ``rms_de`` and ``values``, per parameter name its ``value``, ``kept`` and
    ``range``; else None).

    Example:
        >>> wl = np.arange(400.0, 701.0, 10.0)
        >>> r = diffuse_reflectance(wl, melanin=[[0.02, 0.1]], eumelanin=0.6, hemoglobin=0.02)
        >>> to_rec709 = np.array([[3.2406, -1.5372, -0.4986], [-0.9689, 1.8758, 0.0415], [0.0557, -0.2040, 1.0570]])
        >>> albedo = xyz(wl, r) @ to_rec709.T                  # (1, 2, 3) linear Rec.709
        >>> m = maps(albedo, eumelanin=0.6)
        >>> m["melanin"].round(2), bool(m["in_gamut"].all())
        (array([[0.02, 0.1 ]]), True)
    """
    a = _real(albedo_rgb, "albedo_rgb")
    if a.ndim != 3 or a.shape[-1] != 3:
        raise SkinError(f"albedo_rgb: must have shape (H, W, 3) (linear Rec.709 per texel), got shape {a.shape}")
    shape = a.shape[:2]
    m = None
    if mask is not None:
        mk = np.asarray(mask)
        if mk.dtype.kind not in "biuf":
            raise SkinError(f"mask: not an array of flags (dtype {mk.dtype})")
        if mk.shape != shape:
            raise SkinError(f"mask: must have the texture's shape {shape} (H, W), got shape {mk.shape}")
        m = (mk != 0).reshape(-1)
    if eumelanin is not None:
        try:
            eumelanin = float(eumelanin)
        except (TypeError, ValueError):
            raise SkinError(f"eumelanin: {eumelanin!r} is not a number in [0, 1] (or None: fitted)") from None
    if eumelanin_regions is not None and (
        isinstance(eumelanin_regions, bool) or not isinstance(eumelanin_regions, (int, np.integer)) or eumelanin_regions < 0
    ):
        raise SkinError(f"eumelanin_regions: {eumelanin_regions!r} is not a block size in [4, 4096] texels (or None)")
    gains = (1.0, 1.0, 1.0)
    if isinstance(exposure, str):
        kind = exposure.strip().lower()
        if kind not in ("auto", "auto-rgb"):
            raise SkinError(f"exposure: {exposure!r} is not a gain in [0.125, 2], three gains, 'auto' or 'auto-rgb'")
    else:
        try:
            g = np.asarray(exposure, dtype=np.float64).reshape(-1)
        except (TypeError, ValueError):
            raise SkinError(f"exposure: {exposure!r} is not a gain in [0.125, 2], three gains, 'auto' or 'auto-rgb'") from None
        if g.size not in (1, 3):
            raise SkinError(f"exposure: {g.size} gains given; one (R = G = B) or three (R, G, B), each in [0.125, 2]")
        gains = tuple(float(x) for x in np.broadcast_to(g, (3,)))
        kind = "gains"
    if not isinstance(model, str):
        raise SkinError(f"model: {model!r} is not one of 'seed', 'full', 'auto'")
    if isinstance(parameters, str):
        parameters = [parameters]
    if parameters is not None:
        parameters = [str(p) for p in parameters]
    d = _native.maps(
        a.reshape(-1, 3),
        shape[1],
        m,
        eumelanin,
        None if eumelanin_regions is None else int(eumelanin_regions),
        kind,
        gains,
        model,
        parameters,
        bool(thin_epidermis),
        None if thin_epidermis_mm is None else float(thin_epidermis_mm),
        None if thin_hemoglobin_max is None else float(thin_hemoglobin_max),
        bool(cache),
        threads,
    )
    summary = dict(d["summary"])
    beta = (
        d["eumelanin_map"].reshape(shape)
        if "eumelanin_map" in d
        else np.full(shape, summary["eumelanin"], dtype=np.float64)
    )
    out: dict[str, Any] = {
        "melanin": d["melanin"].reshape(shape),
        "eumelanin": beta,
        "hemoglobin": d["hemoglobin"].reshape(shape),
        "delta_e": d["delta_e"].reshape(shape),
        "in_gamut": np.asarray(d["in_gamut"], dtype=bool).reshape(shape),
        "fitted": np.asarray(d["fitted"], dtype=bool).reshape(shape),
        "thin_epidermis": np.asarray(d["thin_epidermis"], dtype=bool).reshape(shape),
        "summary": summary,
    }
    return out


def xyz(wavelength_nm: ArrayLike, reflectance: ArrayLike) -> Array:
    """CIE 1931 XYZ under D65 of reflectance spectra: (..., M) on a uniform (M,) nm grid → (..., 3).

    A perfect white reflector gives Y = 1; the spectrum is held constant beyond its grid.

    Example:
        >>> xyz(np.arange(400.0, 701.0, 10.0), np.ones(31)).round(4)
        array([0.9505, 1.    , 1.0888])
    """
    lam = _real(wavelength_nm, "wavelength_nm")
    if lam.ndim != 1:
        raise SkinError(f"wavelength_nm: must be one axis (M,), got shape {lam.shape}")
    r = _real(reflectance, "reflectance")
    if r.ndim == 0 or r.shape[-1] != lam.shape[0]:
        raise SkinError(f"reflectance: last axis must have the {lam.shape[0]} wavelengths, got shape {r.shape}")
    return _native.xyz(lam, r.reshape(-1, lam.shape[0])).reshape(r.shape[:-1] + (3,))


def _triples(x: ArrayLike, name: str) -> Array:
    a = _real(x, name)
    if a.ndim == 0 or a.shape[-1] != 3:
        raise SkinError(f"{name}: last axis must hold 3 values, got shape {a.shape}")
    return a


def lab(
    wavelength_nm: ArrayLike | None = None,
    reflectance: ArrayLike | None = None,
    *,
    xyz: ArrayLike | None = None,
    srgb: str | Sequence[str] | None = None,
) -> Array:
    """CIELAB (D65 white) of spectra (``wavelength_nm``, ``reflectance`` as for :func:`xyz`),
    of XYZ triples (``xyz=``, (..., 3), Y = 1 for white) or of ``"#RRGGBB"`` colours (``srgb=``).

    Example:
        >>> lab(np.arange(400.0, 701.0, 10.0), np.ones(31)).round(3)
        array([100.,   0.,   0.])
    """
    given = [reflectance is not None, xyz is not None, srgb is not None]
    if sum(given) != 1:
        raise SkinError("reflectance: give exactly one of (wavelength_nm, reflectance), xyz= or srgb=")
    if srgb is not None:
        hexes = [srgb] if isinstance(srgb, str) else list(srgb)
        out = _native.lab_from_srgb(hexes)
        return out[0] if isinstance(srgb, str) else out
    if xyz is None:
        if wavelength_nm is None:
            raise SkinError("wavelength_nm: needed with reflectance")
        xyz_values = globals()["xyz"](wavelength_nm, reflectance)
    else:
        xyz_values = _triples(xyz, "xyz")
    return _native.lab_from_xyz(xyz_values.reshape(-1, 3)).reshape(xyz_values.shape)


def srgb(lab: ArrayLike) -> str | list[str]:
    """``"#RRGGBB"`` (sRGB, clipped to its gamut) of CIELAB (3,) or (N, 3).

    Example:
        >>> srgb([100.0, 0.0, 0.0])
        '#ffffff'
    """
    t = _triples(lab, "lab")
    out = _native.srgb_from_lab(t.reshape(-1, 3))
    return out[0] if t.ndim == 1 else out


def delta_e_2000(lab1: ArrayLike, lab2: ArrayLike) -> Array:
    """CIEDE2000 colour difference of CIELAB triples (..., 3); the two broadcast.

    Example:
        >>> float(delta_e_2000([50, 2.6772, -79.7751], [50, 0, -82.7485])).__round__(4)
        2.0425
    """
    a = _triples(lab1, "lab1")
    b = _triples(lab2, "lab2")
    try:
        shape = np.broadcast_shapes(a.shape, b.shape)
    except ValueError:
        raise SkinError(f"lab2: shape {b.shape} does not broadcast with lab1's {a.shape}") from None
    a = np.broadcast_to(a, shape).reshape(-1, 3)
    b = np.broadcast_to(b, shape).reshape(-1, 3)
    return _native.delta_e_2000(a, b).reshape(shape[:-1])


def ita(lab: ArrayLike) -> Array:
    """Individual typology angle ITA° = atan((L* − 50)/b*) in degrees of CIELAB triples (..., 3).

    Example:
        >>> float(ita([60.0, 10.0, 10.0])).__round__(1)
        45.0
    """
    t = _triples(lab, "lab")
    return _native.ita(t.reshape(-1, 3)).reshape(t.shape[:-1])


def presets() -> list[dict[str, Any]]:
    """Every named skin (usable as ``preset=``): name, source, sRGB, CIELAB, ITA° and parameters.

    Example:
        >>> [p["name"] for p in presets()][:3]
        ['paper', 'medium', 'dark']
    """
    return list(_native.presets())
