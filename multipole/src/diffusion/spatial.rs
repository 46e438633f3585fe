//! From a layer stack's spectrum to its spatial [`Profile`]: the knobs ([`DiffusionOptions`]), the
//! construction, and a converged reference to measure a knob setting's error against.
//!
//! R(r) = head(r) + remainder(r): the top layer's first source pair in closed form in r, plus the
//! inverse Hankel transform (`hankel`) of the rest of the stacked spectrum R̂(q) − head̂(q), which
//! decays fast in q. The outer radius is where the cumulative energy — closed form for the head,
//! trapezoid over the inverted remainder — reaches `energy_fraction` of the total.

use crate::diffusion::dipole::Dipole;
use crate::diffusion::hankel::{HankelTable, Pchip, frequency_cutoff};
use crate::diffusion::medium::pole_energy_within;
use crate::diffusion::profile::Profile;
use crate::diffusion::slab::Poles;
use crate::diffusion::stack::{DiffusionLayer, Stack};
use crate::error::{MultipoleError, check_option, check_range};
use std::f64::consts::PI;

/// Smallest table radius, mm (docs/physics.md §8: from about 1e-3 mm).
pub const R_MIN_MM: f64 = 1e-3;

/// Knobs of a diffusion profile computation (the multipole's poles, the radial table and the inverse
/// Hankel transform); every approximation here has one. The exact method's knobs sit beside these in
/// [`crate::skin::DiffusionOptions`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DiffusionOptions {
    /// Poles of each slab's multipole (default `Poles::Exact`).
    pub poles: Poles,
    /// Radial samples of the table, geometric from 1e-3 mm to the outer radius (default 256; ≥ 2).
    pub radial_samples: usize,
    /// Outer radius, mm; `None` (default) = the radius holding `energy_fraction` of the energy.
    pub r_max_mm: Option<f64>,
    /// Energy fraction defining the outer radius when `r_max_mm` is `None` (default 0.999).
    pub energy_fraction: f64,
    /// Gauss–Legendre nodes per 2π/ρ panel of the inverse transform (default 5; 1–64).
    pub transform_nodes: usize,
    /// Radii at which the inverse transform is evaluated before interpolation (default 48; 2–4096).
    pub transform_radii: usize,
    /// Spectrum cutoff: stop at Q where |F(Q)| Q² < tolerance × peak (default 1e-5; [1e-16, 0.1]).
    pub transform_tolerance: f64,
}

impl Default for DiffusionOptions {
    fn default() -> Self {
        Self {
            poles: Poles::Exact,
            radial_samples: 256,
            r_max_mm: None,
            energy_fraction: 0.999,
            transform_nodes: 5,
            transform_radii: 48,
            transform_tolerance: 1e-5,
        }
    }
}

impl DiffusionOptions {
    /// A converged setting used as the reference by `skin::profile_error` for the total and r₉₉ (Exact
    /// poles, 12 nodes per panel, 96 transform radii, tolerance 1e-13, 1024 radial samples; R(r) itself
    /// is compared with `reference_reflectance`).
    #[must_use]
    pub fn reference() -> Self {
        Self {
            radial_samples: 1024,
            transform_nodes: 12,
            transform_radii: 96,
            transform_tolerance: 1e-13,
            ..Self::default()
        }
    }

    /// Check every knob; the error names the knob and its range.
    pub fn validate(&self) -> Result<(), MultipoleError> {
        check_option(
            "radial_samples",
            self.radial_samples as f64,
            2.0,
            1e6,
            "[2, 1e6]",
        )?;
        check_option(
            "energy_fraction",
            self.energy_fraction,
            0.5,
            0.999_999,
            "[0.5, 0.999999]",
        )?;
        check_option(
            "transform_nodes",
            self.transform_nodes as f64,
            1.0,
            64.0,
            "[1, 64]",
        )?;
        check_option(
            "transform_radii",
            self.transform_radii as f64,
            2.0,
            4096.0,
            "[2, 4096]",
        )?;
        check_option(
            "transform_tolerance",
            self.transform_tolerance,
            1e-16,
            0.1,
            "[1e-16, 0.1]",
        )?;
        if let Poles::Count(n) = self.poles {
            check_option("poles", n as f64, 0.0, 1e5, "Count(0..=100000)")?;
        }
        if let Some(r) = self.r_max_mm {
            check_range("r_max (mm)", r, 2.0 * R_MIN_MM, 1e4, "[0.002, 1e4]")?;
        }
        Ok(())
    }
}

/// The remainder of a stack's profile, inverted on coarse radii.
struct Remainder {
    radii: Vec<f64>,
    interpolant: Pchip,
    /// Cumulative ∫₀^{r_j} 2πr remainder dr (trapezoid) at each coarse radius.
    cumulative: Vec<f64>,
}

impl Remainder {
    fn compute(stack: &Stack, opts: &DiffusionOptions, window: f64) -> Self {
        let table = HankelTable::shared(opts.transform_nodes, opts.transform_radii);
        let radii: Vec<f64> = table.unit_radii().iter().map(|x| x * window).collect();
        let values = if stack.layers().len() == 1
            && matches!(stack.top(), DiffusionLayer::SemiInfinite(_))
        {
            // A lone dipole is entirely closed form: nothing to invert.
            vec![0.0; radii.len()]
        } else {
            let f = |q: f64| stack.remainder_transform(q, opts.poles);
            let q_max = frequency_cutoff(f, 0.5 / window, 1e5, opts.transform_tolerance);
            table.invert(window, q_max, f).0
        };
        let mut cumulative = Vec::with_capacity(radii.len());
        let mut acc = 0.0;
        cumulative.push(0.0);
        for j in 1..radii.len() {
            acc += PI
                * (radii[j] - radii[j - 1])
                * (radii[j] * values[j] + radii[j - 1] * values[j - 1]);
            cumulative.push(acc);
        }
        Self {
            interpolant: Pchip::new(radii.clone(), values),
            radii,
            cumulative,
        }
    }

    fn eval(&self, r: f64) -> f64 {
        self.interpolant.eval(r)
    }

    fn cumulative(&self, r: f64) -> f64 {
        let n = self.radii.len();
        if r >= self.radii[n - 1] {
            return self.cumulative[n - 1];
        }
        let j = self.radii.partition_point(|&x| x <= r).max(1);
        let (r0, r1) = (self.radii[j - 1], self.radii[j]);
        let t = (r - r0) / (r1 - r0);
        self.cumulative[j - 1] + t * (self.cumulative[j] - self.cumulative[j - 1])
    }
}

/// Closed-form energy of the top layer's first source pair within radius r.
fn head_cumulative(stack: &Stack, r: f64) -> f64 {
    stack.head_scale()
        * match stack.top() {
            DiffusionLayer::Slab(s) => {
                let st = s.medium().sigma_tr();
                let z0 = s.source_depth_mm();
                let zv = -z0 - 2.0 * s.medium().extrapolation_mm(s.a_boundaries().0);
                0.5 * s.scattered_weight()
                    * s.medium().albedo_prime()
                    * (pole_energy_within(z0, r, st) - pole_energy_within(zv, r, st))
            }
            DiffusionLayer::SemiInfinite(d) => d.reflectance_within(r),
        }
}

/// A first window radius (mm): the largest `fraction` radius of any layer's medium taken as a
/// semi-infinite index-matched dipole. `stack_profile` widens it until it holds the energy asked for.
fn window_estimate(stack: &Stack, fraction: f64) -> f64 {
    stack
        .layers()
        .iter()
        .map(|l| Dipole::with_a(*l.medium(), 1.0).radius_for_energy(fraction))
        .fold(0.0, f64::max)
        .clamp(10.0 * R_MIN_MM, 1e3)
}

/// The spatial profile of a stack with the knobs `opts` (module doc).
pub fn stack_profile(stack: &Stack, opts: &DiffusionOptions) -> Result<Profile, MultipoleError> {
    opts.validate()?;
    stack_profile_checked(stack, opts)
}

/// [`stack_profile`] with `opts` already validated (a caller computing many profiles checks its
/// knobs once).
pub(crate) fn stack_profile_checked(
    stack: &Stack,
    opts: &DiffusionOptions,
) -> Result<Profile, MultipoleError> {
    let total = stack.total_reflectance(opts.poles);
    let cum = |rem: &Remainder, r: f64| head_cumulative(stack, r) + rem.cumulative(r);
    let (rem, r_max) = match opts.r_max_mm {
        Some(r) => (Remainder::compute(stack, opts, r), r),
        None => {
            // Widen the window until it holds the energy fraction of the exact total (q = 0); the
            // cumulative is closed form for the head and a trapezoid for the remainder (≈ 1e-5).
            let target = opts.energy_fraction * total;
            // The estimate is asked for a quarter of the missing energy, so one pass almost always suffices.
            let mut window = window_estimate(stack, 1.0 - 0.25 * (1.0 - opts.energy_fraction));
            let mut rem = Remainder::compute(stack, opts, window);
            for _ in 0..8 {
                if cum(&rem, window) >= target || window >= 1e3 {
                    break;
                }
                window = (window * 1.3).min(1e3);
                rem = Remainder::compute(stack, opts, window);
            }
            let target = target.min(cum(&rem, window));
            let (mut lo, mut hi) = (0.0, window);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if cum(&rem, mid) < target {
                    lo = mid
                } else {
                    hi = mid
                }
            }
            (rem, hi.max(4.0 * R_MIN_MM))
        }
    };
    let r_min = R_MIN_MM.min(r_max / 100.0);
    let n = opts.radial_samples;
    let ratio = (r_max / r_min).powf(1.0 / (n - 1) as f64);
    let mut radii = Vec::with_capacity(n);
    let mut values = Vec::with_capacity(n);
    let mut clamped = 0;
    let mut r = r_min;
    for i in 0..n {
        let ri = if i == n - 1 { r_max } else { r };
        let v = stack.head_reflectance_mm2(ri) + rem.eval(ri);
        // Converged values are ≥ 0; a negative one is numerical (truncated transform): clamp and count.
        let v = if v.is_finite() && v >= 0.0 {
            v
        } else {
            clamped += 1;
            0.0
        };
        radii.push(ri);
        values.push(v);
        r *= ratio;
    }
    Ok(Profile::from_table(radii, values, total)?.with_clamped(clamped))
}

/// The stack's R(r) at the given radii (mm⁻²) by direct, converged quadrature (16-node Gauss panels
/// of width π/r_max up to the 1e-14 cutoff, J0 from `libm`): the reference for knob errors.
pub fn reference_reflectance(stack: &Stack, poles: Poles, radii_mm: &[f64]) -> Vec<f64> {
    let r_hi = radii_mm.iter().copied().fold(1.0, f64::max);
    let f = |q: f64| stack.reflectance_transform(q, poles) - stack.head_transform(q);
    let q_max = frequency_cutoff(f, 0.1 / r_hi, 1e5, 1e-14);
    let (gx, gw) = crate::diffusion::hankel::gauss_legendre(16);
    let h = PI / r_hi;
    let panels = (q_max / h).ceil() as usize;
    let mut nodes = Vec::with_capacity(panels * 16);
    for p in 0..panels {
        for (x, w) in gx.iter().zip(&gw) {
            let q = h * (p as f64 + 0.5 * (x + 1.0));
            nodes.push((q, 0.5 * h * w * q * f(q)));
        }
    }
    radii_mm
        .iter()
        .map(|&r| {
            let rem: f64 = nodes.iter().map(|(q, wf)| wf * libm::j0(q * r)).sum();
            stack.head_reflectance_mm2(r) + rem / (2.0 * PI)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diffusion::{medium::Medium, slab::Slab};

    fn skin_like(sa_epi: f64, sa_derm: f64) -> Stack {
        let epi = Slab::new(Medium::new(sa_epi, 5.3).unwrap(), 0.25, 1.4, 1.0).unwrap();
        let derm = Dipole::new(Medium::new(sa_derm, 5.3).unwrap(), 1.0).unwrap();
        Stack::new(vec![
            DiffusionLayer::Slab(epi),
            DiffusionLayer::SemiInfinite(derm),
        ])
        .unwrap()
    }

    #[test]
    fn lone_dipole_profile_is_the_closed_form() {
        let d = Dipole::new(Medium::new(0.1, 1.0).unwrap(), 1.4).unwrap();
        let p = stack_profile(
            &Stack::new(vec![DiffusionLayer::SemiInfinite(d)]).unwrap(),
            &DiffusionOptions::default(),
        )
        .unwrap();
        for (r, v) in p.radii_mm().iter().zip(p.reflectance_per_mm2()) {
            assert!((v - d.reflectance_mm2(*r)).abs() <= 1e-14 * d.reflectance_mm2(0.0));
        }
        // Outer radius: 99.9% of the closed-form energy.
        let f = d.reflectance_within(p.r_max_mm()) / d.total_reflectance();
        assert!((f - 0.999).abs() < 1e-6, "{f}");
    }

    #[test]
    fn default_knobs_are_within_their_stated_error_of_the_reference() {
        // Stated accuracy of the defaults (BENCHMARKS.md): energy-density error ≤ 1e-3 of the total.
        let st = skin_like(0.3, 0.05);
        let p = stack_profile(&st, &DiffusionOptions::default()).unwrap();
        let radii: Vec<f64> = p.radii_mm().iter().step_by(8).copied().collect();
        let exact = reference_reflectance(&st, Poles::Exact, &radii);
        for (r, e) in radii.iter().zip(&exact) {
            let err = 2.0 * PI * r * r * (p.eval(*r) - e).abs() / p.total();
            assert!(err < 1e-3, "r = {r}: {} vs {e}", p.eval(*r));
        }
        assert_eq!(p.clamped_samples(), 0);
        // The table holds the requested energy fraction of the exact total.
        let held = p.table_integral() / p.total();
        assert!((held - 0.999).abs() < 1e-3, "{held}");
    }

    #[test]
    fn options_are_validated() {
        let st = skin_like(0.3, 0.05);
        for bad in [
            DiffusionOptions {
                radial_samples: 1,
                ..Default::default()
            },
            DiffusionOptions {
                transform_nodes: 0,
                ..Default::default()
            },
            DiffusionOptions {
                transform_tolerance: f64::NAN,
                ..Default::default()
            },
            DiffusionOptions {
                r_max_mm: Some(-1.0),
                ..Default::default()
            },
            DiffusionOptions {
                energy_fraction: 1.0,
                ..Default::default()
            },
        ] {
            let e = stack_profile(&st, &bad).unwrap_err().to_string();
            assert!(e.contains("outside"), "{e}");
        }
    }

    #[test]
    fn explicit_outer_radius_is_respected() {
        let p = stack_profile(
            &skin_like(0.3, 0.05),
            &DiffusionOptions {
                r_max_mm: Some(3.0),
                radial_samples: 64,
                ..Default::default()
            },
        )
        .unwrap();
        assert_eq!(p.radii_mm().len(), 64);
        assert!((p.r_max_mm() - 3.0).abs() < 1e-12);
        assert!((p.radii_mm()[0] - R_MIN_MM).abs() < 1e-15);
    }
}
