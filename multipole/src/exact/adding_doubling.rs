//! Adding-doubling: exact plane-parallel transport in layered slabs ([vdH80]; [Prahl95] for tissue;
//! docs/physics.md §10). The medium is a [`LayeredMedium`] of one refractive index throughout.
//!
//! The radiative transfer equation for a stack of homogeneous layers, each with its own absorption σa,
//! scattering σs (mm⁻¹), Henyey–Greenstein anisotropy g and thickness (the last may be semi-infinite),
//! one refractive index throughout the stack and smooth Fresnel interfaces to the media above and below,
//! solved deterministically for azimuthally symmetric light:
//!
//! - angles: `quadrature_points` directions per hemisphere; Radau on [0, 1] for an index-matched stack,
//!   otherwise Gauss on [0, μc] and Radau on [μc, 1], μc the critical cosine inside, so μ = 1 (the
//!   normally incident beam) is a node and the Fresnel kink falls between the two rules;
//! - phase function: HG redistribution by Legendre series with the δ-M truncation (M = quadrature points);
//! - each layer: R and T in closed form from the eigenmodes of the discrete-ordinate equations
//!   (module `modes`; a semi-infinite layer without iterating), or, for a conservative layer (albedo 1
//!   after δ-M), diamond initialisation of a layer thinner than the smallest μ, then doubling; layers and
//!   interfaces combined by the adding equations with directional operators.
//!
//! The knob is `quadrature_points`; the δ-M truncation and the angular discretisation are its only
//! approximations (measured: see the tests and BENCHMARKS.md `## Exact method`).
//!
//! Symbols: `sigma_a` σa (mm⁻¹), `sigma_s` σs (mm⁻¹, not reduced), `g` HG anisotropy, `albedo` a = σs/σt,
//! `tau` optical thickness σt·d, `eta` refractive index of the stack, `mu` μ = cos θ inside the stack.

mod eigen;
mod layer;
mod layer_cache;
mod matrix;
mod memo;
mod modes;
mod quadrature;
mod split;

pub use layer_cache::LAYER_CACHE_BYTES;
pub use split::{LayerTotals, skin_layer_totals};

pub use crate::error::AddingDoublingError;
use crate::error::MultipoleError;
use crate::layered::{Layer, LayeredMedium};
use layer::{Angles, LayerBuild, Operator};
use matrix::Mat;
use skin_optics::{SkinParams, Wavelength, WavelengthGrid};
use std::rc::Rc;

pub use crate::layered::DEFAULT_G;

/// Default number of quadrature directions per hemisphere: worst error against 64 points ≤ 0.75% over
/// 400–700 nm for C_m in [0, 0.5] (0.03% for light skin); 16 points give up to 2.5% for dark skin,
/// where low-albedo epidermis makes the δ-M truncation matter (BENCHMARKS.md `## Exact method`).
pub const DEFAULT_QUADRATURE_POINTS: usize = 24;

/// Largest supported number of quadrature directions per hemisphere.
pub const MAX_QUADRATURE_POINTS: usize = 64;

fn check(
    name: &'static str,
    value: f64,
    ok: bool,
    range: &'static str,
) -> Result<f64, AddingDoublingError> {
    if ok && !value.is_nan() {
        Ok(value)
    } else {
        Err(AddingDoublingError::OutOfRange { name, value, range })
    }
}

/// Solver knobs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AddingDoublingOptions {
    quadrature_points: usize,
    g: f64,
    cache_layers: bool,
}

impl AddingDoublingOptions {
    /// `quadrature_points`: directions per hemisphere, even, in [4, 64]; `g`: the HG anisotropy used
    /// for skin layers by [`skin_totals`] (see [`LayeredMedium::skin`]), in [0, 0.99].
    pub fn new(quadrature_points: usize, g: f64) -> Result<Self, AddingDoublingError> {
        if !(4..=MAX_QUADRATURE_POINTS).contains(&quadrature_points)
            || !quadrature_points.is_multiple_of(2)
        {
            return Err(AddingDoublingError::OutOfRange {
                name: "quadrature_points",
                value: quadrature_points as f64,
                range: "even numbers in [4, 64]",
            });
        }
        check("g", g, (0.0..=0.99).contains(&g), "[0, 0.99]")?;
        Ok(Self {
            quadrature_points,
            g,
            cache_layers: false,
        })
    }

    /// The same options with the per-thread layer cache on or off (module `layer_cache`: a layer
    /// whose albedo, optical thickness and g were solved before on this thread is reused; the totals
    /// are bit for bit the same, only faster where consecutive solves share a layer, as a fit's
    /// Jacobian does). Default off.
    #[must_use]
    pub fn with_layer_cache(self, on: bool) -> Self {
        Self {
            cache_layers: on,
            ..self
        }
    }

    /// Whether the layer cache is on.
    #[must_use]
    pub fn caches_layers(&self) -> bool {
        self.cache_layers
    }

    /// Quadrature directions per hemisphere.
    #[must_use]
    pub fn quadrature_points(&self) -> usize {
        self.quadrature_points
    }

    /// HG anisotropy assumed for skin layers.
    #[must_use]
    pub fn g(&self) -> f64 {
        self.g
    }
}

impl Default for AddingDoublingOptions {
    fn default() -> Self {
        Self {
            quadrature_points: DEFAULT_QUADRATURE_POINTS,
            g: DEFAULT_G,
            cache_layers: false,
        }
    }
}

/// Totals for a collimated beam at normal incidence, per incident photon.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SlabTotals {
    /// Diffuse reflectance, specular reflection of the top surface excluded (the observable).
    pub diffuse_reflectance: f64,
    /// Specular reflection of the top surface, F_r(0).
    pub specular_reflectance: f64,
    /// Total transmittance out of the bottom (scattered and unscattered; 0 for a semi-infinite stack).
    pub transmittance: f64,
}

impl SlabTotals {
    /// Absorbed fraction, 1 − R_diffuse − R_specular − T.
    #[must_use]
    pub fn absorbed(&self) -> f64 {
        1.0 - self.diffuse_reflectance - self.specular_reflectance - self.transmittance
    }
}

/// The angular grid inside `medium`: split at the critical cosine of the top face if any.
fn angles(medium: &LayeredMedium, eta: f64, quadrature_points: usize) -> Angles {
    let rule = quadrature::slab_rule_cached(quadrature_points, critical_cosine(medium, eta));
    Angles::new(rule.nodes.clone(), rule.weights.clone())
}

/// The cosine inside the stack (index `eta`) at which the grid is split: the critical one of the top
/// face, 0 when the stack is not denser than what lies above.
fn critical_cosine(medium: &LayeredMedium, eta: f64) -> f64 {
    if medium.n_above() < eta {
        (1.0 - (medium.n_above() / eta).powi(2)).sqrt()
    } else {
        0.0
    }
}

/// The one refractive index of every layer of `medium`.
///
/// One index for the whole stack is what skin needs (1.4 throughout) and lets every layer share one
/// angular grid; internal index steps are not supported. The grid is split at the critical angle of
/// the top face only: with `n_below` ≠ `n_above` the bottom face's kink falls inside a quadrature
/// interval and converges more slowly in `quadrature_points`.
fn stack_index(medium: &LayeredMedium) -> Result<f64, AddingDoublingError> {
    let eta = medium.layers()[0].n();
    match medium.layers().iter().find(|l| l.n() != eta) {
        Some(l) => Err(AddingDoublingError::OutOfRange {
            name: "layer index n (one index for every layer)",
            value: l.n(),
            range: "the top layer's index",
        }),
        None => Ok(eta),
    }
}

/// Diffuse reflectance, specular reflectance and transmittance of `medium` for a normally incident
/// beam (every layer of one index, see [`stack_index`]).
pub fn solve(
    medium: &LayeredMedium,
    options: &AddingDoublingOptions,
) -> Result<SlabTotals, AddingDoublingError> {
    let eta = stack_index(medium)?;
    let angles = angles(medium, eta, options.quadrature_points);
    let n = angles.n();
    let normal = n - 1; // μ = 1 is the last node of every rule.
    let top = layer::interface(&angles, eta, medium.n_above());
    let specular = top.r_down[(normal, normal)];

    // Fold from the bottom up: a semi-infinite bottom needs reflection only.
    let mu_c = critical_cosine(medium, eta);
    let mut ops = Vec::with_capacity(medium.layers().len());
    for l in medium.layers() {
        ops.push(if options.cache_layers {
            let key = layer_cache::LayerKey::new(
                options.quadrature_points,
                mu_c,
                l.albedo(),
                l.optical_thickness(),
                l.g(),
            );
            layer_cache::cached(key, || build_layer(&angles, l))?
        } else {
            Rc::new(build_layer(&angles, l)?)
        });
    }
    let diffuse;
    let transmittance;
    if medium.is_semi_infinite() {
        let mut below = ops
            .pop()
            .map(|o| o.r_down.clone())
            .unwrap_or_else(|| Mat::zeros(n));
        while let Some(op) = ops.pop() {
            below = op
                .reflect_over(&below)
                .map_err(|_| AddingDoublingError::Singular("adding layers"))?;
        }
        diffuse = escape_through_top(&top, &below, normal)?;
        transmittance = 0.0;
    } else {
        let mut acc = layer::interface(&angles, eta, medium.n_below());
        while let Some(op) = ops.pop() {
            acc = op
                .add(&acc)
                .map_err(|_| AddingDoublingError::Singular("adding layers"))?;
        }
        let whole = top
            .add(&acc)
            .map_err(|_| AddingDoublingError::Singular("adding the top surface"))?;
        diffuse = whole.r_down.column_sum(normal) - specular;
        transmittance = whole.t_down.column_sum(normal);
    }
    let totals = SlabTotals {
        diffuse_reflectance: diffuse,
        specular_reflectance: specular,
        transmittance,
    };
    debug_assert!(totals.diffuse_reflectance.is_finite() && totals.transmittance.is_finite());
    Ok(totals)
}

/// Diffuse flux leaving through the top surface for a unit normally incident beam, given the reflection
/// operator `below` of everything under the surface: T₁₀ (I − R_below R₁₀)⁻¹ R_below T₀₁ e_normal,
/// computed for that one column only.
fn escape_through_top(
    top: &Operator,
    below: &Mat,
    normal: usize,
) -> Result<f64, AddingDoublingError> {
    let n = below.n();
    let entering = top.t_down[(normal, normal)];
    let source: Vec<f64> = below.column(normal).iter().map(|v| v * entering).collect();
    let lhs = below.mul(&top.r_up).identity_minus();
    let up = lhs
        .solve_vec(&source)
        .map_err(|_| AddingDoublingError::Singular("adding the top surface"))?;
    Ok((0..n).map(|i| top.t_up[(i, i)] * up[i]).sum())
}

fn build_layer(angles: &Angles, l: &Layer) -> Result<Operator, AddingDoublingError> {
    let built = layer::homogeneous(angles, l.albedo(), l.optical_thickness(), l.g())
        .map_err(|_| AddingDoublingError::Singular("doubling a layer"))?;
    match built {
        LayerBuild::Done(op) => {
            debug_assert!(op.r_down.is_finite() && op.t_down.is_finite());
            Ok(op)
        }
        LayerBuild::NotConverged => Err(AddingDoublingError::SemiInfiniteWithoutAbsorption {
            sigma_a_per_mm: l.sigma_a(),
        }),
    }
}

/// Exact totals of the skin at one wavelength (normal incidence, per incident photon).
pub fn skin_totals(
    skin: &SkinParams,
    lambda: Wavelength,
    options: &AddingDoublingOptions,
) -> Result<SlabTotals, MultipoleError> {
    Ok(solve(
        &LayeredMedium::skin(skin, lambda, options.g)?,
        options,
    )?)
}

/// Exact total diffuse reflectance of the skin per unit flux *entering* it (the quantity diffusion's R_d
/// stands for): the observable divided by 1 − F_r(0), so `multipole::diffusion::boundary::observable_reflectance`
/// maps it back to [`SlabTotals::diffuse_reflectance`].
pub fn skin_total_reflectance(
    skin: &SkinParams,
    lambda: Wavelength,
    options: &AddingDoublingOptions,
) -> Result<f64, MultipoleError> {
    let t = skin_totals(skin, lambda, options)?;
    Ok(t.diffuse_reflectance / (1.0 - t.specular_reflectance))
}

/// Exact totals of the skin at every wavelength of `grid`, in order, on the calling thread.
pub fn skin_totals_spectrum(
    skin: &SkinParams,
    grid: &WavelengthGrid,
    options: &AddingDoublingOptions,
) -> Result<Vec<SlabTotals>, MultipoleError> {
    grid.iter()
        .map(|lambda| skin_totals(skin, lambda, options))
        .collect()
}

#[cfg(test)]
mod tests;
