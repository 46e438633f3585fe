#![doc = include_str!("../README.md")]

mod colour;
mod error;
mod extended;
mod forward;
pub mod geometry;
mod least_squares;
pub mod maps;
mod measured;
pub mod model;
mod named;
mod nelder_mead;
mod spectrum;

pub use colour::{ColourFit, ColourModel, fit_colour};
pub use error::FitError;
pub use extended::{
    AT_BOUND_FRACTION, CHI2_TOLERANCE, FULL_REFINED_STARTS, FULL_STARTS_MAX, MeasuredColourFit,
    MeasuredFit, MeasuredOptions, SCREENED_TRIALS, SelectionStep, fit_measured,
    fit_measured_colour,
};
pub use geometry::Geometry;
pub use measured::{MAX_NM, MIN_NM, MIN_POINTS, MeasuredSpectrum};
pub use model::{ModelChoice, Parameter};
pub use named::{NamedSkin, named_skins};
pub use spectrum::{SpectrumFit, fit_spectrum};

use multipole::Method;
use nelder_mead::{Budget, distinct_starts, grid_search, minimize};
use skin_optics::{OpticsError, SkinParams};

/// Searched range of the melanin fraction C_m, the physical one of [DJ06].
pub const MELANIN_RANGE: [f64; 2] = [0.0, 0.5];
/// Searched range of the eumelanin blend β_m.
pub const EUMELANIN_RANGE: [f64; 2] = [0.0, 1.0];
/// Searched range of the hemoglobin fraction C_h, the physical one of [DJ06].
pub const HEMOGLOBIN_RANGE: [f64; 2] = [0.001, 0.1];

/// Knobs of a fit. `Default` gives the documented values.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FitOptions {
    /// Forward model passed through to [`multipole::skin::diffuse_reflectance`]. Default [`Method::Exact`]
    /// (adding-doubling totals, right for every skin tone), searched with a cheaper quadrature and
    /// corrected to the full model (module `forward`); [`Method::Multipole`] is the paper's diffusion
    /// (closed-form totals, one stage, reproduces [DJ06]; wrong for dark skin, docs/physics.md §9).
    pub method: Method,
    /// Quadrature points per hemisphere of the adding-doubling model in the search stage (grid,
    /// starts, β_m sweep) of an exact fit; even, in [4, 64]. Default 8 (about 12 times cheaper than the
    /// default 24). A value ≥ the default 24 searches with the full model in a single stage.
    pub search_quadrature_points: usize,
    /// Wavelength step of the search model's spectrum in a two-stage exact colour fit, nm, in (0, 100]
    /// (default 20: colour error 0.18 ΔE00 against 1 nm, removed with the quadrature error by the
    /// correction, which uses [`FitOptions::step_nm`]).
    pub search_step_nm: f64,
    /// Wavelength step of the model spectrum behind a colour, nm, over 400–700 nm (default 10; (0, 100]).
    /// Measured colour error against a 1-nm step, worst over skins spanning the ranges:
    /// 5 nm 0.016, 10 nm 0.046, 20 nm 0.18, 30 nm 0.71 ΔE00.
    pub step_nm: f64,
    /// Coarse grid nodes per search axis (eumelanin, pheomelanin, C_h), each in [2, 64] (default 7 × 7 × 6 = 294 models).
    pub grid: [usize; 3],
    /// Local refinements, started from the best grid nodes in distinct basins (default 6; ≥ 1).
    pub starts: usize,
    /// β_m the prior pulls towards when the data cannot decide (default 0.6; [0, 1]).
    pub beta_prior: f64,
    /// C_h the prior pulls towards when the data cannot decide (default 0.01; [0.001, 0.1]).
    pub hemoglobin_prior: f64,
    /// Prior weight for colour fits: ΔE00 charged per unit of |β_m − prior| or per two decades of
    /// C_h / prior (default 0.01; ≥ 0).
    pub prior_weight_de: f64,
    /// Prior weight for spectrum fits, in reflectance RMS (default 1e-4, a tenth of 1 % noise on a dark skin; ≥ 0).
    pub prior_weight_rms: f64,
    /// Number of β_m values in the ambiguity sweep, 0 = no sweep (default 11: steps of 0.1).
    pub beta_scan: usize,
    /// β_m is "allowed" where the refitted ΔE00 is within this of the best (default 1, about one
    /// just-noticeable difference).
    pub beta_tolerance_de: f64,
    /// β_m is "allowed" where the refitted RMS reflectance is within this of the best (default 0.002).
    pub beta_tolerance_rms: f64,
    /// A colour fit whose ΔE00 exceeds this is reported out of gamut (default 3).
    pub gamut_threshold_de: f64,
    /// A spectrum fit whose RMS reflectance exceeds this is reported out of range (default 0.02).
    pub max_rms: f64,
    /// Skin supplying everything not fitted (ρ_s, γ, epidermis thickness, η, dermis scattering scale).
    pub base: SkinParams,
}

impl Default for FitOptions {
    fn default() -> Self {
        Self {
            method: Method::Exact,
            search_quadrature_points: 8,
            search_step_nm: 20.0,
            step_nm: 10.0,
            grid: [7, 7, 6],
            starts: 6,
            beta_prior: 0.6,
            hemoglobin_prior: 0.01,
            prior_weight_de: 0.01,
            prior_weight_rms: 1e-4,
            beta_scan: 11,
            beta_tolerance_de: 1.0,
            beta_tolerance_rms: 0.002,
            gamut_threshold_de: 3.0,
            max_rms: 0.02,
            base: SkinParams::default(),
        }
    }
}

impl FitOptions {
    /// Check every knob against its range.
    pub fn validate(&self) -> Result<(), FitError> {
        let check = |name, value: f64, ok: bool, range| {
            if ok && value.is_finite() {
                Ok(())
            } else {
                Err(FitError::Option { name, value, range })
            }
        };
        check(
            "step_nm",
            self.step_nm,
            self.step_nm > 0.0 && self.step_nm <= 100.0,
            "(0, 100] nm",
        )?;
        check(
            "search_step_nm",
            self.search_step_nm,
            self.search_step_nm > 0.0 && self.search_step_nm <= 100.0,
            "(0, 100] nm",
        )?;
        for n in self.grid {
            check(
                "grid nodes",
                n as f64,
                (2..=64).contains(&n),
                "[2, 64] per axis",
            )?;
        }
        check("starts", self.starts as f64, self.starts >= 1, "[1, ∞)")?;
        check(
            "search_quadrature_points",
            self.search_quadrature_points as f64,
            (4..=multipole::exact::adding_doubling::MAX_QUADRATURE_POINTS)
                .contains(&self.search_quadrature_points)
                && self.search_quadrature_points.is_multiple_of(2),
            "even numbers in [4, 64]",
        )?;
        check(
            "beta_prior",
            self.beta_prior,
            (0.0..=1.0).contains(&self.beta_prior),
            "[0, 1]",
        )?;
        for (name, v) in [
            ("prior_weight_de", self.prior_weight_de),
            ("prior_weight_rms", self.prior_weight_rms),
            ("beta_tolerance_de", self.beta_tolerance_de),
            ("beta_tolerance_rms", self.beta_tolerance_rms),
        ] {
            check(name, v, v >= 0.0, "[0, ∞)")?;
        }
        check(
            "beta_scan",
            self.beta_scan as f64,
            self.beta_scan != 1,
            "0 or [2, ∞)",
        )?;
        check(
            "gamut_threshold_de",
            self.gamut_threshold_de,
            self.gamut_threshold_de > 0.0,
            "(0, ∞)",
        )?;
        check("max_rms", self.max_rms, self.max_rms > 0.0, "(0, ∞)")?;
        Ok(())
    }
}

/// The β_m values the data allow: those whose refitted residual (C_m and C_h free) stays within
/// `tolerance` of the best fit's, from a sweep of `samples` equally spaced β_m in [0, 1].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BetaRange {
    /// Smallest allowed β_m of the sweep.
    pub min: f64,
    /// Largest allowed β_m of the sweep.
    pub max: f64,
    /// The residual tolerance used (ΔE00 for colours, RMS reflectance for spectra).
    pub tolerance: f64,
    /// Number of β_m values swept.
    pub samples: usize,
}

/// Steepness k of the melanin coordinate map τ(x) = (e^{kx} − 1)/(e^k − 1): k = 3 puts grid nodes
/// both among light skins (x = 0.1 ↔ C = 0.009) and among dark ones, where a steeper map
/// (k = 5 was tried) left dark targets to a false minimum at C_m = 0.5, C_h = 0.1; the slope at
/// x = 0 stays non-zero, so "no melanin" is not an artificial stationary point.
const MELANIN_STEEPNESS: f64 = 3.0;

fn tau(x: f64) -> f64 {
    (MELANIN_STEEPNESS * x).exp_m1() / MELANIN_STEEPNESS.exp_m1()
}

fn tau_inv(t: f64) -> f64 {
    (t.max(0.0) * MELANIN_STEEPNESS.exp_m1()).ln_1p() / MELANIN_STEEPNESS
}

/// Unit-box search coordinates (e, p, h) → (C_m, β_m, C_h).
///
/// The search runs on the eumelanin and pheomelanin fractions C_em = C_m β_m = 0.5 τ(e) and
/// C_pm = C_m (1 − β_m) = 0.5 τ(p), on which the epidermal absorption depends linearly ([DJ06] eq. 1),
/// rather than on (C_m, β_m): there every β_m gives the same skin at C_m = 0, a face of false
/// minima. Points with C_em + C_pm > 0.5 are projected along their ray onto C_m = 0.5 (β_m kept).
/// C_h = 0.001 · 100^h. At C_m = 0, β_m is reported as `beta_default`.
pub(crate) fn search_to_params(x: &[f64; 3], beta_default: f64) -> [f64; 3] {
    let [c_lo, c_hi] = HEMOGLOBIN_RANGE;
    let c_em = MELANIN_RANGE[1] * tau(x[0]);
    let c_pm = MELANIN_RANGE[1] * tau(x[1]);
    let c_m = (c_em + c_pm).min(MELANIN_RANGE[1]);
    let beta = if c_em + c_pm > 0.0 {
        c_em / (c_em + c_pm)
    } else {
        beta_default
    };
    [c_m, beta, c_lo * (c_hi / c_lo).powf(x[2])]
}

/// How far search point `x` lies outside the feasible triangle C_em + C_pm ≤ 0.5, as a fraction of 0.5
/// (0 inside). The objectives add (10 · this)² so the simplex is pushed back inside instead of
/// wandering on the plateau the projection creates.
pub(crate) fn infeasibility(x: &[f64; 3]) -> f64 {
    (tau(x[0]) + tau(x[1]) - 1.0).max(0.0)
}

/// (C_m, β_m, C_h) → search coordinates (inverse of [`search_to_params`] inside the feasible set).
pub(crate) fn params_to_search(p: [f64; 3]) -> [f64; 3] {
    let [c_lo, c_hi] = HEMOGLOBIN_RANGE;
    let m = MELANIN_RANGE[1];
    [
        tau_inv(p[0] * p[1] / m).min(1.0),
        tau_inv(p[0] * (1.0 - p[1]) / m).min(1.0),
        ((p[2].max(c_lo) / c_lo).ln() / (c_hi / c_lo).ln()).clamp(0.0, 1.0),
    ]
}

/// The prior's squared penalty, in squared units of the residual (see the module doc):
/// w² [(β_m − β_prior)² · C_m / (C_m + 0.001) + (log₁₀(C_h / C_h,prior) / 2)²].
pub(crate) fn prior_penalty2(p: [f64; 3], weight: f64, opts: &FitOptions) -> f64 {
    let beta = (p[1] - opts.beta_prior).powi(2) * p[0] / (p[0] + 0.001);
    let blood = (0.5 * (p[2] / opts.hemoglobin_prior).log10()).powi(2);
    weight * weight * (beta + blood)
}

/// `base` with its chromophore fractions replaced, every other constant (and the extended
/// physiology) kept.
pub(crate) fn with_chromophores(base: &SkinParams, p: [f64; 3]) -> Result<SkinParams, OpticsError> {
    base.with_melanin(p[0])?
        .with_eumelanin_blend(p[1])?
        .with_hemoglobin(p[2])
}

/// Budget of the main refinement: 1e-4 of the unit box is below every reported digit.
pub(crate) const REFINE: Budget = Budget {
    x_tol: 1e-4,
    f_tol: 1e-10,
    max_evals: 400,
};

/// Budget of the refinement in the search stage of a two-stage fit: the space-mapping correction
/// refines further, so the search optimum is needed only to well within the search model's own error.
pub(crate) const SEARCH: Budget = Budget {
    x_tol: 1e-3,
    f_tol: 1e-8,
    max_evals: 400,
};

/// Budget of each β_m-sweep refit: the sweep only needs the residual to a few per cent.
const SWEEP: Budget = Budget {
    x_tol: 3e-3,
    f_tol: 1e-6,
    max_evals: 60,
};

/// Global minimum of `objective` over the unit box: coarse grid, then refinement from distinct basins,
/// skipping the remaining starts once `exact(x)` says a refined point already reproduces the data
/// (for colours: ΔE00 below [`EXACT_DE`]; the β_m sweep then reports the equivalent fits).
/// Returns the unit-box point, its objective and the evaluations spent.
pub(crate) fn global_minimum(
    objective: &mut impl FnMut(&[f64; 3]) -> f64,
    exact: impl Fn(&[f64; 3]) -> bool,
    opts: &FitOptions,
    budget: Budget,
) -> ([f64; 3], f64, usize) {
    let grid = grid_search(objective, opts.grid);
    let mut evals = grid.len();
    let spacing = 1.0 / (opts.grid.iter().copied().max().unwrap_or(2) - 1) as f64;
    let mut best = (grid[0].1, grid[0].2);
    for start in distinct_starts(&grid, opts.starts) {
        let m = minimize(objective, start, 0.5 * spacing.max(0.05), budget);
        evals += m.evals;
        if m.f < best.1 {
            best = (m.x, m.f);
        }
        if exact(&best.0) {
            break;
        }
    }
    (best.0, best.1, evals)
}

/// A colour fit this close (ΔE00) reproduces the target exactly for every practical purpose.
pub const EXACT_DE: f64 = 1e-3;

/// Sweep β_m over `opts.beta_scan` values, refitting C_m and C_h at each (starting from the best fit
/// `best`, in physical parameters) with `residual(C_m, β_m, C_h)` (no prior), and return the β_m
/// range whose residual stays within `tolerance` of `best_residual`.
pub(crate) fn beta_sweep(
    residual: &mut impl FnMut(&[f64; 3]) -> f64,
    best: [f64; 3],
    best_residual: f64,
    tolerance: f64,
    opts: &FitOptions,
) -> (Option<BetaRange>, usize) {
    let n = opts.beta_scan;
    if n < 2 {
        return (None, 0);
    }
    let [c_lo, c_hi] = HEMOGLOBIN_RANGE;
    // Refit coordinates: (τ⁻¹(C_m / 0.5), h) as in [`search_to_params`], with β_m held.
    let to_params = |y: &[f64; 2], beta: f64| {
        [
            MELANIN_RANGE[1] * tau(y[0]),
            beta,
            c_lo * (c_hi / c_lo).powf(y[1]),
        ]
    };
    let start = [
        tau_inv(best[0] / MELANIN_RANGE[1]).min(1.0),
        params_to_search(best)[2],
    ];
    let betas: Vec<f64> = (0..n).map(|k| k as f64 / (n - 1) as f64).collect();
    let mut evals = 0;
    let (mut lo, mut hi) = (best[1], best[1]);
    // Continuation outward from the fitted β_m in both directions: each refit starts at its
    // neighbour's solution, which stays in the same basin as β_m moves.
    let split = betas.partition_point(|b| *b < best[1]);
    let upward: Vec<f64> = betas[split..].to_vec();
    let downward: Vec<f64> = betas[..split].iter().rev().copied().collect();
    for side in [upward, downward] {
        let mut warm = start;
        for beta in side {
            let mut f2 = |y: &[f64; 2]| residual(&to_params(y, beta)).powi(2);
            let m = minimize(&mut f2, warm, 0.05, SWEEP);
            evals += m.evals;
            warm = m.x;
            if m.f.sqrt() > best_residual + tolerance {
                // The connected range ends here.
                break;
            }
            lo = lo.min(beta);
            hi = hi.max(beta);
        }
    }
    (
        Some(BetaRange {
            min: lo,
            max: hi,
            tolerance,
            samples: n,
        }),
        evals,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn search_box_maps_to_the_physical_ranges_and_back() {
        assert_eq!(search_to_params(&[0.0, 0.0, 0.0], 0.6), [0.0, 0.6, 0.001]);
        let hi = search_to_params(&[1.0, 0.0, 1.0], 0.6);
        assert!((hi[0] - 0.5).abs() < 1e-15 && hi[1] == 1.0 && (hi[2] - 0.1).abs() < 1e-15);
        // Both melanins at their maximum: projected onto C_m = 0.5, half and half.
        assert_eq!(search_to_params(&[1.0, 1.0, 0.0], 0.6)[..2], [0.5, 0.5]);
        assert!((tau(0.1) - 0.01833).abs() < 1e-5, "{}", tau(0.1));
        for p in [
            [0.002, 0.5, 0.01],
            [0.3, 0.9, 0.04],
            [0.05, 0.6, 0.02],
            [0.5, 0.0, 0.1],
        ] {
            let back = search_to_params(&params_to_search(p), 0.6);
            for (a, b) in back.iter().zip(p) {
                assert!((a - b).abs() < 1e-14 * b.max(1.0), "{back:?} vs {p:?}");
            }
        }
    }

    #[test]
    fn options_are_validated() {
        assert!(FitOptions::default().validate().is_ok());
        let bad = FitOptions {
            step_nm: 0.0,
            ..FitOptions::default()
        };
        assert!(matches!(
            bad.validate(),
            Err(FitError::Option {
                name: "step_nm",
                ..
            })
        ));
        let bad = FitOptions {
            grid: [7, 1, 6],
            ..FitOptions::default()
        };
        assert!(bad.validate().is_err());
    }

    #[test]
    fn chromophores_replace_only_the_fractions() {
        let base = SkinParams::default().with_oxygenation(0.75).unwrap();
        let s = with_chromophores(&base, [0.1, 0.2, 0.03]).unwrap();
        assert_eq!(
            (s.melanin(), s.eumelanin_blend(), s.hemoglobin()),
            (0.1, 0.2, 0.03)
        );
        assert_eq!(s.oxygenation(), 0.75);
        assert_eq!(s.oiliness(), base.oiliness());
    }
}
