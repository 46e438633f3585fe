//! Fit to a measured spectrum: weighted least squares in reflectance at the measured wavelengths.

use super::forward::{Forward, space_mapping};
use super::{
    BetaRange, ColourModel, FitError, FitOptions, MeasuredSpectrum, REFINE, SEARCH, beta_sweep,
    global_minimum, infeasibility, prior_penalty2, search_to_params, with_chromophores,
};
use skin_optics::lab::Lab;
use skin_optics::{SkinParams, Wavelength};
use std::cell::RefCell;

/// Result of [`fit_spectrum`].
#[derive(Debug, Clone, PartialEq)]
pub struct SpectrumFit {
    /// The fitted skin (C_m, β_m, C_h fitted; the rest from [`FitOptions::base`]).
    pub skin: SkinParams,
    /// Model diffuse reflectance of the fitted skin at each measured wavelength.
    pub model: Vec<f64>,
    /// Weighted RMS reflectance residual √(Σ wᵢ (Rᵢ − R̂ᵢ)² / Σ wᵢ).
    pub rms: f64,
    /// False when `rms` exceeds [`FitOptions::max_rms`]: the model cannot reproduce this spectrum.
    pub within_tolerance: bool,
    /// The fitted skin's colour under D65 (its model spectrum over 400–700 nm).
    pub lab: Lab,
    /// The β_m values the spectrum allows (within [`FitOptions::beta_tolerance_rms`]), if swept.
    pub beta_range: Option<BetaRange>,
    /// Objective evaluations spent (each one model spectrum at the measured wavelengths; search
    /// model and full model together).
    pub evaluations: usize,
    /// Of these, full-model evaluations in the space-mapping correction (0 for a single-stage fit).
    pub full_evaluations: usize,
}

/// Fit C_m, β_m, C_h to a measured reflectance spectrum by weighted least squares (see the module
/// doc for the search, the β_m prior and the tolerance test, and module `forward` for the two-stage
/// exact fit).
pub fn fit_spectrum(
    measured: &MeasuredSpectrum,
    opts: &FitOptions,
) -> Result<SpectrumFit, FitError> {
    opts.validate()?;
    let lambdas = measured
        .lambda_nm()
        .iter()
        .map(|&nm| Wavelength::new(nm))
        .collect::<Result<Vec<_>, _>>()?;
    let weights = measured.relative_weights();
    let weight_sum: f64 = weights.iter().sum();
    let full = Forward::Method(opts.method);
    let search_forward = Forward::search(opts.method, opts.search_quadrature_points);
    let search = search_forward.unwrap_or(full);
    // Reflectance added to the search model's at each wavelength (space mapping; zero until then).
    let shift: RefCell<Vec<f64>> = RefCell::new(vec![0.0; lambdas.len()]);
    let weighted_rms = |model: &[f64]| -> f64 {
        let ss: f64 = model
            .iter()
            .zip(measured.reflectance())
            .zip(&weights)
            .map(|((r_hat, r), w)| w * (r - r_hat).powi(2))
            .sum();
        (ss / weight_sum).sqrt()
    };
    let failure: RefCell<Option<FitError>> = RefCell::new(None);
    // Weighted RMS residual of the skin with parameters p = (C_m, β_m, C_h), or +∞ if the model failed.
    let rms = |p: &[f64; 3]| -> f64 {
        let model = with_chromophores(&opts.base, *p)
            .map_err(FitError::from)
            .and_then(|s| search.spectrum(&s, &lambdas));
        match model {
            Ok(mut m) => {
                for (r, b) in m.iter_mut().zip(shift.borrow().iter()) {
                    *r += b;
                }
                weighted_rms(&m)
            }
            Err(e) => {
                failure.borrow_mut().get_or_insert(e);
                f64::INFINITY
            }
        }
    };
    let (w, prior) = (opts.prior_weight_rms, opts.beta_prior);
    let penalties =
        |x: &[f64; 3], p: [f64; 3]| prior_penalty2(p, w, opts) + (10.0 * infeasibility(x)).powi(2);
    let mut objective = |x: &[f64; 3]| {
        let p = search_to_params(x, prior);
        rms(&p).powi(2) + penalties(x, p)
    };
    let budget = if search_forward.is_some() {
        SEARCH
    } else {
        REFINE
    };
    let (mut x, _, mut evaluations) = global_minimum(&mut objective, |_| false, opts, budget);
    let mut full_evaluations = 0;
    if search_forward.is_some() {
        let full_at = |x: &[f64; 3]| -> Result<(Vec<f64>, f64), FitError> {
            let p = search_to_params(x, prior);
            let skin = with_chromophores(&opts.base, p)?;
            let f = full.spectrum(&skin, &lambdas)?;
            let c = search.spectrum(&skin, &lambdas)?;
            let diff = f.iter().zip(&c).map(|(f, c)| f - c).collect();
            Ok((diff, weighted_rms(&f).powi(2) + penalties(x, p)))
        };
        let (xm, search_evals, full_evals) = space_mapping(
            x,
            &mut objective,
            |b| *shift.borrow_mut() = b,
            full_at,
            REFINE,
        )?;
        x = xm;
        evaluations += search_evals + 2 * full_evals;
        full_evaluations = full_evals;
    }
    let p = search_to_params(&x, prior);
    let skin = with_chromophores(&opts.base, p)?;
    let model = full.spectrum(&skin, &lambdas)?;
    let best = weighted_rms(&model);
    let (beta_range, sweep_evals) =
        beta_sweep(&mut |p| rms(p), p, best, opts.beta_tolerance_rms, opts);
    evaluations += sweep_evals + 1;
    if let Some(e) = failure.into_inner() {
        return Err(e);
    }
    let colour = ColourModel::new(opts.step_nm, opts.method, opts.base)?;
    Ok(SpectrumFit {
        model,
        lab: colour.lab(&skin)?,
        skin,
        rms: best,
        within_tolerance: best <= opts.max_rms,
        beta_range,
        evaluations,
        full_evaluations,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use multipole::Method;

    /// Gaussian deviates from a seeded SplitMix64 (Box–Muller), so the test needs no RNG crate.
    struct Noise(u64);
    impl Noise {
        fn uniform(&mut self) -> f64 {
            self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
        }
        fn gaussian(&mut self) -> f64 {
            let u1 = self.uniform().max(1e-300);
            let u2 = self.uniform();
            (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
        }
    }

    /// A spectrum from known parameters plus 1 % (relative, Gaussian) noise on 61
    /// wavelengths, weighted by the inverse noise variance, fits back to C_m within 10 % and β_m
    /// within 0.1 where melanin shapes the spectrum (C_m ≥ 0.02), and C_h within 15 % where the
    /// dermis shows through (C_m ≤ 0.1; at C_m = 0.3 the whole range of C_h changes this spectrum by
    /// under 0.1 %, so C_h is not determined and the prior decides). For both forward models, each
    /// fitting spectra it generated (the exact one through its two-stage search).
    #[test]
    fn noisy_spectrum_fits_back_to_its_parameters() {
        for method in [Method::Exact, Method::Multipole] {
            noisy_spectrum_round_trip(method);
        }
    }

    /// Weights all 1e308 (their sum overflows) or all 1e-320 (the weighted squares underflow) once
    /// gave "RMS = 0" and a wrong skin; scaling every weight by one factor must change nothing.
    #[test]
    fn fit_with_weights_all_1e308_or_all_1e_320_equals_the_unweighted_fit() {
        let opts = FitOptions {
            method: Method::Multipole,
            ..FitOptions::default()
        };
        let skin = with_chromophores(&opts.base, [0.1, 0.7, 0.03]).unwrap();
        let lambda: Vec<f64> = (0..7).map(|i| 400.0 + 50.0 * f64::from(i)).collect();
        // The model's own spectrum, perturbed so the best RMS is not zero.
        let r: Vec<f64> = lambda
            .iter()
            .enumerate()
            .map(|(i, &nm)| {
                let clean = multipole::skin::diffuse_reflectance(
                    &skin,
                    Wavelength::new(nm).unwrap(),
                    opts.method,
                )
                .unwrap();
                clean * if i % 2 == 0 { 1.02 } else { 0.98 }
            })
            .collect();
        let fit = |w: Option<f64>| {
            let weights = w.map(|w| vec![w; lambda.len()]);
            fit_spectrum(
                &MeasuredSpectrum::new(lambda.clone(), r.clone(), weights).unwrap(),
                &opts,
            )
            .unwrap()
        };
        let plain = fit(None);
        assert!(plain.rms > 1e-3, "{}", plain.rms);
        for w in [1e308, 1e-320] {
            let f = fit(Some(w));
            // Relative weights are exactly 1, so the whole fit is bitwise the unweighted one.
            assert_eq!(f.rms, plain.rms, "weights {w}");
            assert_eq!(f.skin, plain.skin, "weights {w}");
        }
    }

    fn noisy_spectrum_round_trip(method: Method) {
        let opts = FitOptions {
            method,
            ..FitOptions::default()
        };
        let mut noise = Noise(2026);
        for truth in [
            [0.02, 0.5, 0.01],
            [0.1, 0.7, 0.03],
            [0.3, 0.9, 0.04],
            [0.05, 0.3, 0.005],
        ] {
            let skin = with_chromophores(&opts.base, truth).unwrap();
            let lambda: Vec<f64> = (0..61).map(|i| 400.0 + 5.0 * i as f64).collect();
            let clean: Vec<f64> = lambda
                .iter()
                .map(|&nm| {
                    multipole::skin::diffuse_reflectance(
                        &skin,
                        Wavelength::new(nm).unwrap(),
                        opts.method,
                    )
                    .unwrap()
                })
                .collect();
            let noisy: Vec<f64> = clean
                .iter()
                .map(|r| r * (1.0 + 0.01 * noise.gaussian()))
                .collect();
            // Weights 1/σᵢ² for the relative noise σᵢ = 0.01 Rᵢ: the maximum-likelihood fit.
            let weights = clean.iter().map(|r| (0.01 * r).powi(-2)).collect();
            let measured = MeasuredSpectrum::new(lambda, noisy, Some(weights)).unwrap();
            let fit = fit_spectrum(&measured, &opts).unwrap();
            let s = fit.skin;
            let msg = format!(
                "{method}: truth {truth:?} fit {:?} rms {}",
                [s.melanin(), s.eumelanin_blend(), s.hemoglobin()],
                fit.rms
            );
            assert!((s.melanin() / truth[0] - 1.0).abs() < 0.10, "{msg}");
            if truth[0] <= 0.1 {
                assert!((s.hemoglobin() / truth[2] - 1.0).abs() < 0.15, "{msg}");
            }
            if truth[0] >= 0.02 {
                assert!((s.eumelanin_blend() - truth[1]).abs() < 0.1, "{msg}");
            }
            assert!(fit.within_tolerance, "{msg}");
        }
    }
}
