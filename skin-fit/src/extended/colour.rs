//! Fit to a colour with the instrument's geometry and the model chosen by the data
//! (docs/physics.md §13.3): the colour counterpart of [`super::fit_measured`].
//!
//! The target is a CIELAB colour (D65, CIE 1931 2°) as the instrument reports it: for SCI the
//! colour of the diffuse reflectance plus ρ_s a(cos 8°). The residual is CIEDE2000 written as three
//! terms ([`delta_e_2000_terms`]), so the bounded Levenberg–Marquardt refinement minimises ΔE00²
//! itself. Start: [`fit_colour`] (the seed's global search on the diffuse colour); then the same
//! refinement, `full` starts and `auto` rounds as for a spectrum (module `select`), on the 8-point
//! adding-doubling colour shifted in XYZ to the full model's.
//!
//! **Criterion.** A colour has n = 3 coordinates; `auto` uses the spectrum's criterion with the
//! colour's residual: IC = ΔE00² / σ_c² + k ln 3 + 2 ln C(m, j). σ_c is the colour noise that the
//! reflectance noise σ ([`MeasuredOptions::noise`]) implies: white noise σ on each reflectance of the
//! 400–700 nm grid every [`super::FitOptions::step_nm`] moves ΔE00 by σ √(Σᵢ |∂t/∂Rᵢ|²) in RMS
//! (t the three terms, linearised at the seed fit's spectrum), and σ_c² is a third of its square, so
//! that ΔE00²/σ_c² has mean 3 (= n) under that noise. A candidate is therefore kept when it lowers
//! ΔE00² by more than σ_c² (ln 3 + 2 ln((m − j)/(j + 1))). With more free parameters than
//! coordinates the fitted values are not determined (a valley of equal colours); what the fit
//! measures is whether the model's gamut reaches the colour.

use super::select::{self, Target, ln_binomial};
use super::{MeasuredOptions, SelectionStep, seed_parameters};
use crate::forward::Forward;
use crate::geometry::{Geometry, unit_surface_reflectance};
use crate::model::Parameter;
use crate::{ColourModel, FitError, fit_colour};
use skin_optics::SkinParams;
use skin_optics::color::{Xyz, reflectance_to_xyz};
use skin_optics::lab::{Lab, delta_e_2000_terms};

/// Result of [`fit_measured_colour`].
#[derive(Debug, Clone, PartialEq)]
pub struct MeasuredColourFit {
    /// The fitted skin (free parameters fitted, the rest from the base skin).
    pub skin: SkinParams,
    /// The parameters that were free, seed ones first.
    pub parameters: Vec<Parameter>,
    /// The target colour.
    pub target: Lab,
    /// The colour the instrument sees for the fitted skin (full model).
    pub lab: Lab,
    /// CIEDE2000 between `lab` and `target`.
    pub delta_e: f64,
    /// ΔE00 of the seed model's fit under the same geometry.
    pub seed_delta_e: f64,
    /// Colour noise per coordinate σ_c the criterion uses, ΔE00 (module doc).
    pub noise_delta_e: f64,
    /// The rounds of the `auto` selection (residuals in ΔE00; empty for `seed` and `full`).
    pub steps: Vec<SelectionStep>,
}

/// Fit a CIELAB `target` with the instrument's geometry and the chosen model (module doc).
pub fn fit_measured_colour(
    target: Lab,
    opts: &MeasuredOptions,
) -> Result<MeasuredColourFit, FitError> {
    opts.validate()?;
    let start = fit_colour(target, &opts.fit)?;
    let unit_surface = match opts.geometry {
        Geometry::Sce => 0.0,
        Geometry::Sci => unit_surface_reflectance(opts.fit.base.eta())?,
    };
    let mut problem = ColourTarget::new(target, opts, unit_surface)?;
    let seed_params = seed_parameters(opts);
    let seed = select::refine(&mut problem, start.skin, &seed_params)?;
    let sigma_c = problem.colour_noise(&seed.0, opts.noise)?;
    let m = Parameter::CANDIDATES.len();
    let n = 3.0_f64;
    let criterion = |de: f64, k: usize, j: usize| {
        (de / sigma_c).powi(2) + k as f64 * n.ln() + 2.0 * ln_binomial(m, j)
    };
    let (parameters, skin, _, steps) =
        select::fit_model(&mut problem, opts, seed, &seed_params, criterion)?;
    let lab = problem.lab(&problem.full, &skin)?;
    Ok(MeasuredColourFit {
        skin,
        parameters,
        target,
        lab,
        delta_e: lab.delta_e_2000(target),
        seed_delta_e: seed.1,
        noise_delta_e: sigma_c,
        steps,
    })
}

/// The target colour, the two colour models and the current XYZ shift.
struct ColourTarget {
    target: Lab,
    full: ColourModel,
    search: Option<ColourModel>,
    shift: [f64; 3],
    /// XYZ of a unit flat reflectance (what the SCI surface term adds per unit).
    white: [f64; 3],
    unit_surface: f64,
    geometry: Geometry,
}

impl ColourTarget {
    fn new(target: Lab, opts: &MeasuredOptions, unit_surface: f64) -> Result<Self, FitError> {
        let f = &opts.fit;
        let full = ColourModel::new(f.step_nm, f.method, f.base)?;
        let search = Forward::search(f.method, f.search_quadrature_points)
            .map(|s| ColourModel::with_forward(f.step_nm, s, f.base))
            .transpose()?;
        let ones = skin_optics::GridSpectrum::new(*full.grid(), vec![1.0; full.grid().len()])?;
        Ok(Self {
            target,
            white: reflectance_to_xyz(&ones).0,
            full,
            search,
            shift: [0.0; 3],
            unit_surface,
            geometry: opts.geometry,
        })
    }

    /// XYZ the instrument sees with colour model `m` (no shift).
    fn seen(&self, m: &ColourModel, skin: &SkinParams) -> Result<[f64; 3], FitError> {
        let surface = match self.geometry {
            Geometry::Sce => 0.0,
            Geometry::Sci => skin.oiliness() * self.unit_surface,
        };
        let xyz = m.xyz(skin)?.0;
        Ok([0, 1, 2].map(|c| xyz[c] + surface * self.white[c]))
    }

    fn lab(&self, m: &ColourModel, skin: &SkinParams) -> Result<Lab, FitError> {
        self.seen(m, skin).map(|x| Lab::from_xyz(Xyz(x)))
    }

    /// σ_c (module doc) at `skin` for reflectance noise `sigma`: the ΔE00 terms' sensitivity to
    /// each grid reflectance, by central differences of ±1e-4 (the terms are smooth there; the
    /// colour is linear in the reflectance and CIELAB's cube root is smooth above black).
    fn colour_noise(&self, skin: &SkinParams, sigma: f64) -> Result<f64, FitError> {
        let spectrum = self.full.spectrum(skin)?;
        let surface = match self.geometry {
            Geometry::Sce => 0.0,
            Geometry::Sci => skin.oiliness() * self.unit_surface,
        };
        let base: Vec<f64> = spectrum.values().iter().map(|r| r + surface).collect();
        let grid = *self.full.grid();
        let lab_of = |r: &[f64]| -> Result<Lab, FitError> {
            let s = skin_optics::GridSpectrum::new(grid, r.to_vec())?;
            Ok(Lab::from_xyz(reflectance_to_xyz(&s)))
        };
        let centre = lab_of(&base)?;
        let h = 1e-4;
        let mut sum = 0.0;
        for i in 0..base.len() {
            let (mut up, mut down) = (base.clone(), base.clone());
            up[i] += h;
            down[i] -= h;
            let (tu, td) = (
                delta_e_2000_terms(lab_of(&up)?, centre),
                delta_e_2000_terms(lab_of(&down)?, centre),
            );
            sum += (0..3)
                .map(|c| ((tu[c] - td[c]) / (2.0 * h)).powi(2))
                .sum::<f64>();
        }
        Ok(sigma * (sum / 3.0).sqrt())
    }
}

impl Target for ColourTarget {
    fn shifted_residuals(&mut self, skin: &SkinParams) -> Result<Vec<f64>, FitError> {
        let m = self.search.as_ref().unwrap_or(&self.full);
        let xyz = self.seen(m, skin)?;
        let shifted = Xyz([0, 1, 2].map(|c| xyz[c] + self.shift[c]));
        Ok(delta_e_2000_terms(Lab::from_xyz(shifted), self.target).to_vec())
    }

    fn reshift(&mut self, skin: &SkinParams) -> Result<f64, FitError> {
        let full = self.seen(&self.full, skin)?;
        if let Some(search) = &self.search {
            let cheap = self.seen(search, skin)?;
            self.shift = [0, 1, 2].map(|c| full[c] - cheap[c]);
        }
        Ok(Lab::from_xyz(Xyz(full)).delta_e_2000(self.target))
    }

    fn has_search(&self) -> bool {
        self.search.is_some()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{FitOptions, ModelChoice};
    use multipole::Method;

    fn options(model: ModelChoice) -> MeasuredOptions {
        MeasuredOptions {
            geometry: Geometry::Sci,
            model,
            fit: FitOptions {
                method: Method::Multipole,
                beta_scan: 0,
                ..FitOptions::default()
            },
            ..MeasuredOptions::default()
        }
    }

    /// The SCI colour of `skin` as the fit's own model computes it.
    fn colour_of(skin: &SkinParams, opts: &MeasuredOptions) -> Lab {
        let unit = unit_surface_reflectance(skin.eta()).unwrap();
        let t = ColourTarget::new(Lab::from_xyz(Xyz([0.3; 3])), opts, unit).unwrap();
        t.lab(&t.full, skin).unwrap()
    }

    fn seed_skin() -> SkinParams {
        let s = SkinParams::default().with_melanin(0.05).unwrap();
        s.with_hemoglobin(0.02).unwrap().with_oiliness(0.3).unwrap()
    }

    /// A skin with a thin epidermis and more blood: its SCI colour (L* 61, a* 15.6, b* 15.3) lies
    /// ΔE00 5.0 outside the seed model's gamut (measured).
    fn thin_skin() -> SkinParams {
        let s = SkinParams::default().with_melanin(0.05).unwrap();
        s.with_hemoglobin(0.05)
            .unwrap()
            .with_epidermis_thickness_mm(0.06)
            .unwrap()
    }

    /// Tolerance of a colour the model produces, fitted back: the refinement stops when a step
    /// gains under 1e-7 of the cost ΔE00², which leaves ΔE00 ≈ 1e-6 at a reachable colour
    /// (measured < 1e-5 for these skins with both forward models; the exact fit's space mapping
    /// reproduces the full model at its fixed point). 0.01 keeps a hundredfold margin and is a
    /// hundredth of a just-noticeable difference, far below the criterion's σ_c ≈ 0.3.
    const ROUND_TRIP_DE: f64 = 0.01;

    #[test]
    fn seed_colour_round_trips_and_auto_keeps_the_seed() {
        let opts = options(ModelChoice::Auto);
        let fit = fit_measured_colour(colour_of(&seed_skin(), &opts), &opts).unwrap();
        assert!(fit.delta_e < ROUND_TRIP_DE, "ΔE00 {}", fit.delta_e);
        assert_eq!(fit.parameters.len(), 4, "{:?}", fit.steps);
        // σ = 0.005 per reflectance on 31 wavelengths: about a third of a ΔE00 per coordinate.
        assert!(
            (0.1..1.0).contains(&fit.noise_delta_e),
            "{}",
            fit.noise_delta_e
        );
    }

    #[test]
    fn auto_reaches_a_colour_beyond_the_seed_gamut() {
        let opts = options(ModelChoice::Auto);
        let fit = fit_measured_colour(colour_of(&thin_skin(), &opts), &opts).unwrap();
        assert!(fit.seed_delta_e > 3.0, "seed ΔE00 {}", fit.seed_delta_e);
        assert!(fit.delta_e < ROUND_TRIP_DE, "ΔE00 {}", fit.delta_e);
        assert!(
            fit.parameters.len() > 4 && fit.steps[0].accepted,
            "{:?}",
            fit.steps
        );
    }

    /// The default exact model (two-stage: 8-point search shifted to the full model).
    #[test]
    fn exact_full_model_round_trips_a_colour_beyond_the_seed_gamut() {
        let mut opts = options(ModelChoice::Full);
        opts.fit.method = Method::Exact;
        let fit = fit_measured_colour(colour_of(&thin_skin(), &opts), &opts).unwrap();
        assert!(fit.delta_e < ROUND_TRIP_DE, "ΔE00 {}", fit.delta_e);
        assert_eq!(fit.parameters.len(), 11);
    }

    #[test]
    fn bad_noise_is_a_typed_error() {
        let opts = MeasuredOptions {
            noise: 0.0,
            ..options(ModelChoice::Auto)
        };
        let e = fit_measured_colour(Lab::from_xyz(Xyz([0.3; 3])), &opts).unwrap_err();
        assert!(matches!(e, FitError::Option { name: "noise", .. }), "{e}");
    }
}
