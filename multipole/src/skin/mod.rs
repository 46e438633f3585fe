//! Two-layer skin ([DJ06]): an epidermis slab of the given thickness (index `skin.eta()` above it,
//! matched below) over a semi-infinite dermis (dipole with A = 1), stacked in the frequency domain.

use crate::diffusion::boundary::observable_reflectance;
use crate::diffusion::profile::Profile;
use crate::diffusion::slab::Poles;
use crate::diffusion::spatial::{
    DiffusionOptions, reference_reflectance, stack_profile, stack_profile_checked,
};
use crate::diffusion::stack::Stack;
use crate::error::MultipoleError;
use crate::layered::{DEFAULT_G, LayeredMedium};
use rayon::prelude::*;
use skin_optics::{SkinParams, Wavelength, WavelengthGrid};
use std::fmt;
use std::str::FromStr;

mod explain;
mod options;
mod shape;
mod shape_table;
pub mod thin_slab;
pub use explain::{DIFFUSION_OK, Explanation, explain};
pub use options::ProfileOptions;
pub use shape::{
    DEFAULT_SHAPE_ESCAPES, ExactShape, MAX_SHAPE_PHOTONS, SHAPE_BINS, SHAPE_R_MAX_MM, SHAPE_R0_MM,
    SHAPE_SEED, exact_profile, layer_scales, medium_table_profile, monte_carlo_shape,
    shape_photons, shape_profile, shape_radii, table_profile,
};
pub use shape_table::{
    ShapeTable, ShapeTableOptions, TABLE_MAX_ALPHA, TABLE_MAX_PATH, TABLE_MIN_ALPHA, TABLE_TAU_MAX,
    TABLE_TAU_MIN, cached_table,
};

/// How the skin's diffuse reflectance is computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum Method {
    /// Exact plane-parallel transport by adding-doubling ([Prahl95], [vdH80]; HG g = 0.9,
    /// σs = σs'/(1 − g), Fresnel boundaries; `crate::exact::adding_doubling` with default options) for the
    /// totals, which diffusion overestimates two- to threefold for dark skin. Profiles: the exact
    /// radial shape from the shape table scaled to the exact total ([`ExactShape::Table`]). The default.
    #[default]
    Exact,
    /// Donner & Jensen's multipole diffusion with frequency-domain layer stacking ([DJ05], [DJ06]):
    /// the paper's model.
    Multipole,
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Method::Exact => f.write_str("exact"),
            Method::Multipole => f.write_str("multipole"),
        }
    }
}

impl FromStr for Method {
    type Err = MultipoleError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "exact" => Ok(Method::Exact),
            "multipole" => Ok(Method::Multipole),
            _ => Err(MultipoleError::UnknownMethod(s.to_string())),
        }
    }
}

/// The diffusion stack of `skin` at `lambda`: [`LayeredMedium::skin`] solved by diffusion, an
/// epidermis slab (η_top = skin η, η_bottom = 1 so A = 1) over a semi-infinite dermis (A = 1: index
/// matched to the epidermis).
pub fn stack(skin: &SkinParams, lambda: Wavelength) -> Result<Stack, MultipoleError> {
    Stack::from_medium(&LayeredMedium::skin(skin, lambda, DEFAULT_G)?)
}

/// The model's total diffuse reflectance R_d per unit flux *entering* the skin, dimensionless, in (0, 1).
pub fn total_reflectance(
    skin: &SkinParams,
    lambda: Wavelength,
    method: Method,
) -> Result<f64, MultipoleError> {
    total_reflectance_at_g(skin, lambda, method, DEFAULT_G)
}

/// [`total_reflectance`] with both layers' Henyey–Greenstein anisotropy `g` in [0, 0.99]
/// (`Method::Exact`: adding-doubling at that g; diffusion depends on σs' only).
pub fn total_reflectance_at_g(
    skin: &SkinParams,
    lambda: Wavelength,
    method: Method,
    g: f64,
) -> Result<f64, MultipoleError> {
    medium_total_reflectance(&LayeredMedium::skin(skin, lambda, g)?, method)
}

/// The exact method's medium of `skin` at `lambda`: its layers at `opts.phase_g` under
/// `opts.surface`.
pub fn exact_medium(
    skin: &SkinParams,
    lambda: Wavelength,
    opts: &ProfileOptions,
) -> Result<LayeredMedium, MultipoleError> {
    Ok(LayeredMedium::skin(skin, lambda, opts.phase_g)?.with_surface(opts.surface))
}

/// [`total_reflectance`] of a skin whose layers are already built (`LayeredMedium::skin`, at its
/// layers' own g): adding-doubling of `medium`'s totals per unit flux entering, R_d / (1 − R_spec),
/// or the multipole stack of its σa and σs' ([DJ06] eq. 9 at q = 0).
pub fn medium_total_reflectance(
    medium: &LayeredMedium,
    method: Method,
) -> Result<f64, MultipoleError> {
    use crate::exact::adding_doubling::{AddingDoublingOptions, DEFAULT_QUADRATURE_POINTS, solve};
    match method {
        Method::Exact => {
            let g = medium.layers().first().map_or(DEFAULT_G, |l| l.g());
            let t = solve(
                medium,
                &AddingDoublingOptions::new(DEFAULT_QUADRATURE_POINTS, g)?,
            )?;
            Ok(t.diffuse_reflectance / (1.0 - t.specular_reflectance))
        }
        Method::Multipole => Ok(Stack::from_medium(medium)?.total_reflectance(Poles::Exact)),
    }
}

/// The observable: diffuse reflectance per unit *incident* flux at normal incidence, specular
/// excluded, (1 − F_r(0)) R_d, dimensionless (what a spectrophotometer or a Monte Carlo reports).
pub fn diffuse_reflectance(
    skin: &SkinParams,
    lambda: Wavelength,
    method: Method,
) -> Result<f64, MultipoleError> {
    Ok(observable_reflectance(
        total_reflectance(skin, lambda, method)?,
        skin.eta(),
    ))
}

/// The radial profile R(r) of `skin` at `lambda` (per unit flux entering; mm⁻²) with the knobs `opts`.
/// `Method::Exact` uses the shape `opts.exact_shape` (default [`ExactShape::Table`]; see
/// [`ExactShape`] for the choices).
pub fn profile(
    skin: &SkinParams,
    lambda: Wavelength,
    method: Method,
    opts: &ProfileOptions,
) -> Result<Profile, MultipoleError> {
    opts.validate()?;
    profile_checked(skin, lambda, method, opts)
}

/// [`profile`] with `opts` already validated.
fn profile_checked(
    skin: &SkinParams,
    lambda: Wavelength,
    method: Method,
    opts: &ProfileOptions,
) -> Result<Profile, MultipoleError> {
    match method {
        Method::Exact => exact_profile(skin, lambda, opts.exact_shape, opts),
        Method::Multipole => stack_profile_checked(&stack(skin, lambda)?, &opts.diffusion),
    }
}

/// One profile per wavelength of a grid, computed in parallel (rayon) across wavelengths.
#[derive(Debug, Clone, PartialEq)]
pub struct SpectralProfiles {
    grid: WavelengthGrid,
    profiles: Vec<Profile>,
}

impl SpectralProfiles {
    /// Profiles of `skin` at every wavelength of `grid`. With `Method::Exact` and the run-time
    /// Monte Carlo shape ([`ExactShape::MonteCarlo`]), shapes are traced every `opts.shape_step_nm`
    /// (rounded to a multiple of the grid step; always at both ends) and mixed linearly in between;
    /// every row keeps its own exact total.
    pub fn new(
        skin: &SkinParams,
        grid: &WavelengthGrid,
        method: Method,
        opts: &ProfileOptions,
    ) -> Result<Self, MultipoleError> {
        opts.validate()?;
        let lambdas: Vec<Wavelength> = grid.iter().collect();
        let profiles = match (method, opts.exact_shape) {
            (Method::Exact, ExactShape::MonteCarlo { escapes }) => {
                monte_carlo_rows(skin, grid, escapes, opts)?
            }
            _ => lambdas
                .par_iter()
                .map(|&l| profile_checked(skin, l, method, opts))
                .collect::<Result<Vec<_>, _>>()?,
        };
        Ok(Self {
            grid: *grid,
            profiles,
        })
    }

    /// The wavelength grid.
    #[must_use]
    pub fn grid(&self) -> &WavelengthGrid {
        &self.grid
    }

    /// The profiles, one per grid wavelength in order.
    #[must_use]
    pub fn profiles(&self) -> &[Profile] {
        &self.profiles
    }

    /// The profile at grid index `i` (panics if `i` ≥ grid length, like slice indexing).
    #[must_use]
    pub fn profile(&self, i: usize) -> &Profile {
        &self.profiles[i]
    }
}

/// Rows of [`SpectralProfiles`] with Monte Carlo shapes every `step_nm` (see there).
fn monte_carlo_rows(
    skin: &SkinParams,
    grid: &WavelengthGrid,
    escapes: u64,
    opts: &ProfileOptions,
) -> Result<Vec<Profile>, MultipoleError> {
    let n = grid.len();
    let step_nm = opts.shape_step_nm;
    let totals = (0..n)
        .into_par_iter()
        .map(|i| {
            medium_total_reflectance(
                &exact_medium(skin, grid.wavelength(i), opts)?,
                Method::Exact,
            )
        })
        .collect::<Result<Vec<_>, _>>()?;
    let stride = ((step_nm / grid.step_nm()).round() as usize).max(1);
    let mut anchors: Vec<usize> = (0..n).step_by(stride).collect();
    if anchors.last() != Some(&(n - 1)) {
        anchors.push(n - 1);
    }
    let shapes = anchors
        .par_iter()
        .map(|&i| {
            let medium = exact_medium(skin, grid.wavelength(i), opts)?;
            monte_carlo_shape(&medium, escapes, totals[i])
        })
        .collect::<Result<Vec<_>, _>>()?;
    (0..n)
        .map(|i| {
            // The anchor pair around row i (a single anchor when the grid has one wavelength).
            let k = anchors.partition_point(|&a| a <= i).saturating_sub(1);
            let (a, b) = (anchors[k], anchors[(k + 1).min(anchors.len() - 1)]);
            let t = if b > a {
                (i - a) as f64 / (b - a) as f64
            } else {
                0.0
            };
            let (sa, sb) = (&shapes[k], &shapes[(k + 1).min(anchors.len() - 1)]);
            let mixed: Vec<f64> = sa
                .iter()
                .zip(sb)
                .map(|(x, y)| (1.0 - t) * x + t * y)
                .collect();
            shape_profile(&mixed, totals[i])
        })
        .collect()
}

/// Error of one knob setting against the converged reference, for the time-versus-error chart.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KnobError {
    /// max over r of |2πr² (R − R_ref)| / R_tot,ref: the error of the energy per ln r, relative to the
    /// total (scale free; evaluated with `Profile::eval` at 400 log-spaced radii in [1e-3, r_max]).
    pub max_energy_density_error: f64,
    /// |R_tot − R_tot,ref| / R_tot,ref (poles only: the total comes from q = 0).
    pub total_relative_error: f64,
    /// |r₉₉ − r₉₉,ref| / r₉₉,ref.
    pub r99_relative_error: f64,
}

/// Measure the error of `opts` for `skin` at `lambda` against a converged reference
/// (`Poles::Exact`, direct quadrature with `libm::j0`, see `spatial::reference_reflectance`).
/// `Method::Exact` profiles invert the same transforms with scaled layers, so this measures their knob
/// error too (the method argument is accepted for symmetry).
pub fn profile_error(
    skin: &SkinParams,
    lambda: Wavelength,
    method: Method,
    opts: &ProfileOptions,
) -> Result<KnobError, MultipoleError> {
    let _ = method;
    let st = stack(skin, lambda)?;
    let test = stack_profile(&st, &opts.diffusion)?;
    let reference = stack_profile(&st, &DiffusionOptions::reference())?;
    let r_hi = test.r_max_mm().min(reference.r_max_mm());
    let n = 400;
    let radii: Vec<f64> = (0..n)
        .map(|i| {
            crate::diffusion::spatial::R_MIN_MM
                * (r_hi / crate::diffusion::spatial::R_MIN_MM).powf(i as f64 / (n - 1) as f64)
        })
        .collect();
    let exact = reference_reflectance(&st, Poles::Exact, &radii);
    let total_ref = reference.total();
    let max_err = radii
        .iter()
        .zip(&exact)
        .map(|(&r, &e)| 2.0 * std::f64::consts::PI * r * r * (test.eval(r) - e).abs() / total_ref)
        .fold(0.0, f64::max);
    Ok(KnobError {
        max_energy_density_error: max_err,
        total_relative_error: (test.total() - total_ref).abs() / total_ref,
        r99_relative_error: (test.radius_99_mm() - reference.radius_99_mm()).abs()
            / reference.radius_99_mm(),
    })
}

#[cfg(test)]
mod tests;
