//! The radial shape of `Method::Exact` profiles. The total always comes from adding-doubling; the
//! shape by default from the shape table (exact transport tabulated once per (g, n), module
//! `shape_table`), else from a run-time layered Monte Carlo (where the table does not apply, or
//! when asked for) or from diffusion (rescaled as a whole or per layer, for comparison).

use super::{Method, stack};
use crate::diffusion::boundary::observable_reflectance;
use crate::diffusion::profile::Profile;
use crate::diffusion::slab::Poles;
use crate::diffusion::spatial::stack_profile;
use crate::diffusion::stack::Response;
use crate::error::MultipoleError;
use crate::exact::adding_doubling::{AddingDoublingOptions, LayerTotals, skin_layer_totals};
use crate::exact::montecarlo::{self, McOptions, RadialGrid};
use crate::layered::{LayeredMedium, Surface};
use crate::skin::ProfileOptions;
use skin_optics::{SkinParams, Wavelength};

/// Escaping photons per wavelength of a run-time Monte Carlo shape, and of the fallback where the
/// shape table does not apply (the accuracy knob: the energy-weighted noise of the shape falls as
/// 1/√escapes).
pub const DEFAULT_SHAPE_ESCAPES: u64 = 4_000;
/// Most photons one Monte Carlo shape may trace, whatever its reflectance (bounds the cost for very
/// dark skin in the blue, where fewer than 1% of photons escape).
pub const MAX_SHAPE_PHOTONS: u64 = 2_000_000;
/// Radius of the central disc of the Monte Carlo shape grid, mm (below the epidermal peak's width).
pub const SHAPE_R0_MM: f64 = 0.002;
/// Outer radius of the Monte Carlo shape grid, mm (beyond the red dermal tail of light skin).
pub const SHAPE_R_MAX_MM: f64 = 50.0;
/// Annuli of the Monte Carlo shape grid (geometric: ≈ 15 per decade of radius).
pub const SHAPE_BINS: usize = 72;
/// Generator seed of the Monte Carlo shapes: fixed, so a profile is a pure function of its inputs.
pub const SHAPE_SEED: u64 = 0x5EED_5111;

/// How `Method::Exact` shapes its radial profile; every variant's total is the exact total.
///
/// The default is [`ExactShape::Table`]: exact transport read from the shape table. The diffusion
/// shapes are kept for comparison: their error is the shape of diffusion *within* a layer, which no
/// scalar per layer can change. For dark skin the epidermis makes almost all of the reflectance and
/// the Monte Carlo puts most of it within 0.03 mm, nearer than diffusion does; for light skin
/// diffusion has too much at 0.03–0.3 mm and too little beyond 0.3 mm (the pencil beam's
/// forward-peaked entry, g = 0.9, which a single dipole source at one transport mean free path
/// cannot represent). Errors of each shape against an independent Monte Carlo: BENCHMARKS.md
/// `## Exact profile table` and `## Diffusion against exact transport`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum ExactShape {
    /// The two-layer multipole profile scaled by one factor to the exact total: keeps diffusion's
    /// split between the epidermis' narrow peak and the dermis' wide tail, which is wrong for dark skin
    /// (the low-albedo epidermis reflects far less, relative to the dermis, than diffusion says).
    RescaledTotal,
    /// Each layer rescaled before stacking: every diffusion response R̂(q), T̂(q) of
    /// the epidermis (both directions) and the dermis is multiplied by exact/diffusion at q = 0, the
    /// exact per-layer totals coming from adding-doubling (`adding_doubling::skin_layer_totals`), then
    /// the stack is folded as usual and the result scaled to the exact two-layer total (a correction
    /// of a few percent: the scalars ignore the angular distributions passed between layers).
    PerLayer,
    /// The shape of the layered Monte Carlo ([WJZ95], `crate::exact::montecarlo`; HG g = 0.9, the model's
    /// two layers and Fresnel boundaries) on a geometric grid ([`SHAPE_R0_MM`] to
    /// [`SHAPE_R_MAX_MM`], [`SHAPE_BINS`] annuli, fixed seed [`SHAPE_SEED`]), scaled to the exact
    /// total: transport is exact, only noise remains. `escapes` is the knob: the photons traced are
    /// escapes / (observable exact reflectance), at most [`MAX_SHAPE_PHOTONS`], so the noise is about
    /// the same for every skin tone. The fallback of `Table`, with [`DEFAULT_SHAPE_ESCAPES`].
    MonteCarlo {
        /// Escaping photons wanted (≥ 100).
        escapes: u64,
    },
    /// The same exact transport read from the universal white-Monte-Carlo table
    /// ([`super::ShapeTable`], built once per (g, n) and cached): no run-time photons. Covers every skin whose layers share σs (dermis scattering scale 1),
    /// any index and epidermal scattering depth σs·d in [`super::TABLE_TAU_MIN`],
    /// [`super::TABLE_TAU_MAX`]; elsewhere it falls back to `MonteCarlo` with
    /// [`DEFAULT_SHAPE_ESCAPES`]. The default.
    Table(super::ShapeTableOptions),
}

impl Default for ExactShape {
    fn default() -> Self {
        Self::Table(super::ShapeTableOptions::default())
    }
}

/// The per-layer factors (exact / diffusion totals at q = 0) of [`ExactShape::PerLayer`] and the
/// exact totals they come from.
pub fn layer_scales(
    skin: &SkinParams,
    lambda: Wavelength,
) -> Result<(Vec<Response>, LayerTotals), MultipoleError> {
    let st = stack(skin, lambda)?;
    let exact = skin_layer_totals(skin, lambda, &AddingDoublingOptions::default())?;
    let epi = st.layers()[0].response(0.0, Poles::Exact);
    let derm = st.layers()[1].response(0.0, Poles::Exact);
    // A diffusion total of 0 (never for valid skin) leaves its layer unscaled rather than dividing by 0.
    let ratio = |e: f64, d: f64| if d > 0.0 { e / d } else { 1.0 };
    let epi_s = Response {
        r_down: ratio(exact.epidermis_r_down, epi.r_down),
        t_down: ratio(exact.epidermis_t_down, epi.t_down),
        r_up: ratio(exact.epidermis_r_up, epi.r_up),
        t_up: ratio(exact.epidermis_t_up, epi.t_up),
    };
    let d = ratio(exact.dermis_r, derm.r_down);
    let derm_s = Response {
        r_down: d,
        t_down: 1.0,
        r_up: d,
        t_up: 1.0,
    };
    Ok((vec![epi_s, derm_s], exact))
}

/// The `Method::Exact` profile of `skin` at `lambda` with the given shape (per unit flux entering, mm⁻²).
/// `opts` are the diffusion knobs of the diffusion shapes (unused by `MonteCarlo`).
pub fn exact_profile(
    skin: &SkinParams,
    lambda: Wavelength,
    shape: ExactShape,
    opts: &ProfileOptions,
) -> Result<Profile, MultipoleError> {
    // One medium for the total and the shape: the coefficients are built once.
    let medium = super::exact_medium(skin, lambda, opts)?;
    let total = || super::medium_total_reflectance(&medium, Method::Exact);
    let (table, total) = match shape {
        ExactShape::RescaledTotal => (
            stack_profile(&stack(skin, lambda)?, &opts.diffusion)?,
            total()?,
        ),
        ExactShape::PerLayer => {
            let (scales, exact) = layer_scales(skin, lambda)?;
            let st = stack(skin, lambda)?.with_scales(scales)?;
            let total = if opts.surface == Surface::Fresnel {
                exact.total
            } else {
                total()?
            };
            (stack_profile(&st, &opts.diffusion)?, total)
        }
        ExactShape::MonteCarlo { escapes } => {
            let total = total()?;
            return shape_profile(&monte_carlo_shape(&medium, escapes, total)?, total);
        }
        ExactShape::Table(table_opts) => {
            let total = total()?;
            if let Some(p) = medium_table_profile(&medium, &table_opts, total)? {
                return Ok(p);
            }
            let escapes = DEFAULT_SHAPE_ESCAPES;
            return shape_profile(&monte_carlo_shape(&medium, escapes, total)?, total);
        }
    };
    rescale(&table, total)
}

/// `table` scaled by `total` / its own total (the table keeps its held fraction of the energy).
fn rescale(table: &Profile, total: f64) -> Result<Profile, MultipoleError> {
    let own = table.total();
    let scale = if own > 0.0 { total / own } else { 0.0 };
    let values = table
        .reflectance_per_mm2()
        .iter()
        .map(|v| v * scale)
        .collect();
    Profile::from_table(table.radii_mm().to_vec(), values, total)
}

/// Photons a Monte Carlo shape traces for `escapes` escaping photons at total reflectance `total`
/// (per unit flux entering) of a skin of index `eta`: at least `escapes`, and beyond that at most
/// [`MAX_SHAPE_PHOTONS`] (a request above the cap is traced as asked, one photon per escape).
#[must_use]
pub fn shape_photons(escapes: u64, total: f64, eta: f64) -> u64 {
    let cap = MAX_SHAPE_PHOTONS.max(escapes);
    let escaping_fraction = observable_reflectance(total, eta);
    if escaping_fraction.is_nan() || escaping_fraction <= 0.0 {
        return cap;
    }
    ((escapes as f64 / escaping_fraction).ceil() as u64).clamp(escapes, cap)
}

/// The Monte Carlo R(r) of the skin `medium` (its layers, g and surface) on the shape grid (one
/// value per annulus, its mean, mm⁻²), normalised to unit energy in the trapezoid rule of
/// [`Profile`] on the annuli's representative radii; `total` (exact, per unit flux entering) sets
/// the photon count.
pub fn monte_carlo_shape(
    medium: &LayeredMedium,
    escapes: u64,
    total: f64,
) -> Result<Vec<f64>, MultipoleError> {
    if !(100..=1_000_000_000_000).contains(&escapes) {
        return Err(MultipoleError::InvalidOption {
            name: "shape escapes",
            value: escapes as f64,
            range: "[100, 1e12]",
        });
    }
    let stack = medium;
    let eta = medium.layers()[0].n();
    let grid = shape_grid()?;
    let photons = shape_photons(escapes, total, eta);
    let opts = McOptions::new(photons, 8, SHAPE_SEED)?.with_grid(grid);
    let values = montecarlo::run(stack, &opts).radial.reflectance_per_mm2;
    let radii = shape_radii()?;
    let integral = Profile::from_table(radii, values.clone(), 1.0)?.table_integral();
    let norm = if integral > 0.0 { 1.0 / integral } else { 0.0 };
    Ok(values.into_iter().map(|v| v * norm).collect())
}

/// The Monte Carlo shape grid.
fn shape_grid() -> Result<RadialGrid, MultipoleError> {
    RadialGrid::geometric(SHAPE_R0_MM, SHAPE_R_MAX_MM, SHAPE_BINS)
}

/// Nodes of shape profiles, mm: the central disc's outer radius, then each annulus' geometric mean
/// radius. At the disc's edge the profile's model (R constant below its first node, p = 2πrR
/// linear from 0) holds exactly the disc's energy πr₀²R̄; a node at r₀/2 would hold a quarter of it,
/// which for the pencil beam's sharp peak in dark skin (half the energy within 0.01 mm) shifted
/// 2–4% of the energy outwards.
pub fn shape_radii() -> Result<Vec<f64>, MultipoleError> {
    let grid = shape_grid()?;
    Ok((0..grid.bins())
        .map(|i| {
            if i == 0 {
                grid.outer_mm(0)
            } else {
                grid.r_mid_mm(i)
            }
        })
        .collect())
}

/// The [`ExactShape::Table`] profile of `skin` at `lambda` with HG anisotropy `g` (the table of
/// that g, built once and cached) scaled to `total`, or `None` where the table does not cover the
/// skin.
pub fn table_profile(
    skin: &SkinParams,
    lambda: Wavelength,
    g: f64,
    opts: &super::ShapeTableOptions,
    total: f64,
) -> Result<Option<Profile>, MultipoleError> {
    medium_table_profile(&LayeredMedium::skin(skin, lambda, g)?, opts, total)
}

/// The table profile of a two-layer `medium` scaled to `total`: `None` unless it is a slab over a
/// half-space, in air, with one σs, g and n in both layers (a [DJ06] skin with dermis scattering
/// scale 1, any g, n or thickness), σs·d and σa/σs inside the table.
pub fn medium_table_profile(
    medium: &LayeredMedium,
    opts: &super::ShapeTableOptions,
    total: f64,
) -> Result<Option<Profile>, MultipoleError> {
    let [top, bottom] = medium.layers() else {
        return Ok(None);
    };
    let (Some(d_mm), None) = (top.thickness_mm(), bottom.thickness_mm()) else {
        return Ok(None);
    };
    let same = top.sigma_s() == bottom.sigma_s() && top.g() == bottom.g() && top.n() == bottom.n();
    if !same || medium.n_above() != 1.0 || top.sigma_s() <= 0.0 || !(0.0..=0.99).contains(&top.g())
    {
        return Ok(None);
    }
    let table = super::cached_table(top.g(), top.n(), opts)?;
    table.profile(top.sigma_s(), top.sigma_a(), bottom.sigma_a(), d_mm, total)
}

/// A profile of total `total` from a shape on [`shape_radii`], cut after the node where the
/// cumulative energy reaches 99.9%: like the multipole tables, the table holds 99.9% of `total`.
pub fn shape_profile(shape: &[f64], total: f64) -> Result<Profile, MultipoleError> {
    profile_from_shape(&shape_radii()?, shape, total)
}

/// A profile of total `total` from mean values `shape` (mm⁻²) at nodes `radii` (mm; the
/// [`shape_radii`] convention), cut after the node where the cumulative energy reaches 99.9%.
pub(super) fn profile_from_shape(
    radii: &[f64],
    shape: &[f64],
    total: f64,
) -> Result<Profile, MultipoleError> {
    let radii = radii.to_vec();
    // Total 1 so that `radius_for_energy(f)` is the radius where the table's cumulative reaches f.
    let full = Profile::from_table(radii.clone(), shape.to_vec(), 1.0)?;
    let integral = full.table_integral();
    if integral <= 0.0 {
        return Profile::from_table(radii[..2].to_vec(), vec![0.0; 2], total);
    }
    let r_end = full.radius_for_energy(0.999 * integral);
    let end = (radii.partition_point(|&r| r < r_end * (1.0 - 1e-12)) + 1).clamp(2, radii.len());
    let scale = total / integral;
    let values = shape[..end].iter().map(|v| v * scale).collect();
    Profile::from_table(radii[..end].to_vec(), values, total)
}
