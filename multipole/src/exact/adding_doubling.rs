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
    let folded = fold(medium, options)?;
    let normal = folded.angles.n() - 1; // μ = 1 is the last node of every rule.
    let totals = folded.totals(normal)?;
    debug_assert!(totals.diffuse_reflectance.is_finite() && totals.transmittance.is_finite());
    Ok(totals)
}

/// The diffuse reflectance of `medium` for a collimated beam at each incidence the angular grid
/// resolves: one entry per quadrature direction inside that refracts out of the top face, from
/// grazing to normal incidence (docs/physics.md §10; the same solve as [`solve`], which keeps
/// only the normal column).
pub fn reflectance_by_angle(
    medium: &LayeredMedium,
    options: &AddingDoublingOptions,
) -> Result<Vec<AngularReflectance>, AddingDoublingError> {
    let folded = fold(medium, options)?;
    let eta = folded.eta;
    let ratio = medium.n_above() / eta;
    (0..folded.angles.n())
        .filter_map(|j| {
            let mu_in = folded.angles.mu[j];
            // Snell: sin θ_out = (η / n_above) sin θ_in; directions beyond the critical one stay inside.
            let sin2_out = (1.0 - mu_in * mu_in) / (ratio * ratio);
            (sin2_out < 1.0).then(|| (j, mu_in, (1.0 - sin2_out).sqrt()))
        })
        .map(|(j, mu_in, mu_out)| {
            let t = folded.totals(j)?;
            Ok(AngularReflectance {
                mu_outside: mu_out,
                mu_inside: mu_in,
                totals: t,
            })
        })
        .collect()
}

/// The diffuse reflectance for one incidence of [`reflectance_by_angle`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AngularReflectance {
    /// cos θ of the incident beam above the surface.
    pub mu_outside: f64,
    /// cos θ of the refracted beam inside.
    pub mu_inside: f64,
    /// Totals per incident photon at this incidence (the specular part is F at this angle).
    pub totals: SlabTotals,
}

impl AngularReflectance {
    /// Diffuse reflectance per unit flux *entering* the skin at this incidence.
    #[must_use]
    pub fn per_entering(&self) -> f64 {
        self.totals.diffuse_reflectance / (1.0 - self.totals.specular_reflectance)
    }
}

/// A layered medium folded into the operators that give any column's totals.
struct Folded {
    eta: f64,
    angles: Angles,
    top: Operator,
    /// The reflection under the top face (semi-infinite), or the whole slab's operator.
    body: Body,
}

enum Body {
    SemiInfinite(Mat),
    Finite(Operator),
}

impl Folded {
    /// Totals for a unit beam arriving along quadrature column `j` (paired with its outside direction).
    fn totals(&self, j: usize) -> Result<SlabTotals, AddingDoublingError> {
        let specular = self.top.r_down[(j, j)];
        Ok(match &self.body {
            Body::SemiInfinite(below) => SlabTotals {
                diffuse_reflectance: escape_through_top(&self.top, below, j)?,
                specular_reflectance: specular,
                transmittance: 0.0,
            },
            Body::Finite(whole) => SlabTotals {
                diffuse_reflectance: whole.r_down.column_sum(j) - specular,
                specular_reflectance: specular,
                transmittance: whole.t_down.column_sum(j),
            },
        })
    }
}

fn fold(
    medium: &LayeredMedium,
    options: &AddingDoublingOptions,
) -> Result<Folded, AddingDoublingError> {
    let eta = stack_index(medium)?;
    let angles = angles(medium, eta, options.quadrature_points);
    let n = angles.n();
    let top = layer::interface(&angles, &medium.surface().reflector(eta, medium.n_above()));

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
    let body = if medium.is_semi_infinite() {
        let mut below = ops
            .pop()
            .map(|o| o.r_down.clone())
            .unwrap_or_else(|| Mat::zeros(n));
        while let Some(op) = ops.pop() {
            below = op
                .reflect_over(&below)
                .map_err(|_| AddingDoublingError::Singular("adding layers"))?;
        }
        Body::SemiInfinite(below)
    } else {
        let mut acc = layer::interface(&angles, &medium.surface().reflector(eta, medium.n_below()));
        while let Some(op) = ops.pop() {
            acc = op
                .add(&acc)
                .map_err(|_| AddingDoublingError::Singular("adding layers"))?;
        }
        Body::Finite(
            top.add(&acc)
                .map_err(|_| AddingDoublingError::Singular("adding the top surface"))?,
        )
    };
    Ok(Folded {
        eta,
        angles,
        top,
        body,
    })
}

/// Diffuse flux leaving through the top surface for a unit beam along column `j` (μ = 1: normal
/// incidence), given the reflection operator `below` of everything under the surface:
/// T₁₀ (I − R_below R₁₀)⁻¹ R_below T₀₁ e_j, computed for that one column only.
fn escape_through_top(top: &Operator, below: &Mat, j: usize) -> Result<f64, AddingDoublingError> {
    let n = below.n();
    let entering = top.t_down[(j, j)];
    let source: Vec<f64> = below.column(j).iter().map(|v| v * entering).collect();
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
