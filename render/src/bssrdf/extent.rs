//! Profile extent and table resolution (docs/physics.md §16.1): each row ends where the energy left
//! beyond it is below a tolerance, and the radius grid has the fewest radii whose piecewise-linear
//! density meets an energy-weighted error target.

use super::table::{MAX_RADII, R_MIN_MM};
use multipole::{MultipoleError, Profile};

/// Radii the search of [`radii_for_error`] starts from (doubling from here).
pub const MIN_SEARCH_RADII: usize = 16;

/// Sub-points per grid interval at which [`interpolation_error`] compares the interpolant.
const SUBPOINTS: usize = 4;

/// Where each row ends, mm: with `tolerance` the radius holding 1 − tolerance of the profile's
/// total (its own end where the profile holds less); without, each profile's own end.
pub fn row_ends_mm(
    profiles: &[Profile],
    tolerance: Option<f64>,
) -> Result<Vec<f64>, MultipoleError> {
    if let Some(t) = tolerance
        && !(t > 0.0 && t <= 0.1)
    {
        return Err(MultipoleError::InvalidOption {
            name: "energy tolerance",
            value: t,
            range: "(0, 0.1]",
        });
    }
    Ok(profiles
        .iter()
        .map(|p| match tolerance {
            // Never below the first node: the table needs one interval per row.
            Some(t) => p
                .radius_for_energy(1.0 - t)
                .max(p.radii_mm().get(1).copied().unwrap_or(0.0))
                .min(p.r_max_mm()),
            None => p.r_max_mm(),
        })
        .collect())
}

/// The geometric grid of `radii` radii from [`R_MIN_MM`] to `r_out_mm` (as the table lays it out).
#[must_use]
pub fn geometric_grid(r_out_mm: f64, radii: usize) -> Vec<f64> {
    let r0 = f64::from(R_MIN_MM);
    let ratio = (r_out_mm / r0).ln() / (radii - 1) as f64;
    (0..radii).map(|i| r0 * (ratio * i as f64).exp()).collect()
}

/// ∫|p_lin − p| dr / ∫ p dr over [R_MIN, end_mm] for p = 2πr R(r) of `profile` and p_lin its
/// linear interpolant on `grid` (the table's model), by [`SUBPOINTS`] points per interval.
#[must_use]
pub fn interpolation_error(profile: &Profile, grid: &[f64], end_mm: f64) -> f64 {
    let p = |r: f64| 2.0 * std::f64::consts::PI * r * profile.eval(r);
    let (mut err, mut energy) = (0.0, 0.0);
    for w in grid.windows(2) {
        let (a, b) = (w[0], w[1].min(end_mm));
        if b <= a {
            break;
        }
        let (pa, pb) = (p(a), p(b));
        let h = (b - a) / SUBPOINTS as f64;
        for k in 0..SUBPOINTS {
            let r = a + (k as f64 + 0.5) * h;
            let lin = pa + (pb - pa) * (r - a) / (b - a);
            let exact = p(r);
            err += (lin - exact).abs() * h;
            energy += exact * h;
        }
    }
    if energy > 0.0 { err / energy } else { 0.0 }
}

/// The fewest radii (16, 32, … up to [`MAX_RADII`]) whose grid to the largest of `ends_mm`
/// interpolates every profile within `target` ([`interpolation_error`]); [`MAX_RADII`] when none does.
pub fn radii_for_error(
    profiles: &[Profile],
    ends_mm: &[f64],
    target: f64,
) -> Result<usize, MultipoleError> {
    if !(target > 0.0 && target <= 0.1) {
        return Err(MultipoleError::InvalidOption {
            name: "radial error target",
            value: target,
            range: "(0, 0.1]",
        });
    }
    let r_out = ends_mm.iter().copied().fold(0.0, f64::max);
    let mut n = MIN_SEARCH_RADII;
    while n < MAX_RADII {
        let grid = geometric_grid(r_out, n);
        let worst = profiles
            .iter()
            .zip(ends_mm)
            .map(|(p, &e)| interpolation_error(p, &grid, e))
            .fold(0.0, f64::max);
        if worst <= target {
            return Ok(n);
        }
        n *= 2;
    }
    Ok(MAX_RADII)
}

#[cfg(test)]
mod tests {
    use super::*;
    use multipole::{Method, ProfileOptions};
    use skin_optics::{Preset, SkinParams, Wavelength};

    fn profiles(method: Method) -> Vec<Profile> {
        let mut out = Vec::new();
        for preset in Preset::ALL {
            for nm in [420.0, 560.0, 700.0] {
                out.push(
                    multipole::skin::profile(
                        &SkinParams::preset(preset),
                        Wavelength::new(nm).unwrap(),
                        method,
                        &ProfileOptions::default(),
                    )
                    .unwrap(),
                );
            }
        }
        out
    }

    /// A truncated row keeps at least 1 − tolerance of the profile's total (the model's R_tot from
    /// q = 0, not the table's integral), for both methods and every preset at three wavelengths;
    /// the only slack is f64 rounding of the cumulative (1e-12).
    #[test]
    fn truncated_profiles_keep_one_minus_tolerance_of_the_energy() {
        for method in [Method::Exact, Method::Multipole] {
            let ps = profiles(method);
            for tol in [1e-3, 1e-2, 5e-2] {
                let ends = row_ends_mm(&ps, Some(tol)).unwrap();
                for (p, &end) in ps.iter().zip(&ends) {
                    let kept = p.energy_within_mm(end) / p.total();
                    assert!(kept >= 1.0 - tol - 1e-12, "{method} tol {tol}: kept {kept}");
                    assert!(end <= p.r_max_mm());
                }
                // A looser tolerance never ends a row further out.
                let tighter = row_ends_mm(&ps, Some(tol / 2.0)).unwrap();
                assert!(ends.iter().zip(&tighter).all(|(a, b)| a <= b));
            }
        }
    }

    /// The grid chosen for a target meets it, and halving the target never gives fewer radii.
    #[test]
    fn radii_meet_the_error_target() {
        let ps = profiles(Method::Exact);
        let ends = row_ends_mm(&ps, Some(1e-3)).unwrap();
        let r_out = ends.iter().copied().fold(0.0, f64::max);
        let mut last = 0;
        for target in [2e-2, 5e-3, 2e-3] {
            let n = radii_for_error(&ps, &ends, target).unwrap();
            assert!(n >= last, "{target}: {n} < {last}");
            last = n;
            if n < MAX_RADII {
                let grid = geometric_grid(r_out, n);
                for (p, &e) in ps.iter().zip(&ends) {
                    assert!(interpolation_error(p, &grid, e) <= target);
                }
            }
        }
        assert!(radii_for_error(&ps, &ends, 0.0).is_err());
        assert!(row_ends_mm(&ps, Some(0.2)).is_err());
    }
}
