//! "White" histories: photons in a non-absorbing half-space of unit scattering coefficient, each
//! escape reported with its exit radius, its path length and the part of that path above each of a
//! set of depths (docs/physics.md §11).
//!
//! When two layers share σs, g and n and differ only in σa, a history's random walk does not depend
//! on the absorption; weighting each escape by exp(−σa₁ l₁ − σa₂ l₂) (l₁ the path above the
//! interface, l₂ below) has the same expectation as the implicit capture of the layered run
//! ([WJZ95] §3.6 weights by σs/σt per interaction, whose product over a path of exponential steps
//! has this mean). One white run therefore serves every absorption pair and, with the path split at
//! several depths, every epidermal thickness. Lengths are in scattering lengths (σs = 1).

use super::Photon;
use super::sampling::{HgSampler, scatter, uniform};
use brdf::fresnel::dielectric_reflectance;
use rand_distr::{Distribution, Exp1};
use rand_xoshiro::Xoshiro256StarStar;

/// The medium of a white run: HG anisotropy `g`, index `n` under air (n = 1), σs = 1.
#[derive(Debug, Clone, Copy)]
pub(crate) struct WhiteMedium {
    pub g: f64,
    pub n: f64,
    /// Histories longer than this (scattering lengths) are dropped: their weight e^(−σa l / σs) is
    /// negligible for every absorption the caller covers.
    pub max_path: f64,
}

/// Trace `photons` white histories from a normal pencil beam at the origin. For every escape through
/// the top face, `on_escape(r, path, above)` receives the exit radius, the total path and the path
/// above each of `depths` (all in scattering lengths). Returns the number of histories dropped at
/// `max_path`.
pub(crate) fn trace_white(
    medium: &WhiteMedium,
    depths: &[f64],
    photons: u64,
    rng: &mut Xoshiro256StarStar,
    mut on_escape: impl FnMut(f64, f64, &[f64]),
) -> u64 {
    let hg = HgSampler::new(medium.g);
    let eta_out = 1.0 / medium.n;
    let mut above = vec![0.0; depths.len()];
    let mut dropped = 0;
    for _ in 0..photons {
        let mut p = Photon::launched(1.0);
        above.fill(0.0);
        let mut path = 0.0;
        loop {
            let s: f64 = Exp1.sample(rng);
            let z_new = p.z + s * p.uz;
            if z_new < 0.0 {
                // Reaches the face. The unused depth is not carried: the exponential step is
                // memoryless, so a fresh draw after a reflection has the same distribution.
                let d = -p.z / p.uz;
                add_above(&mut above, depths, p.z, 0.0, d);
                path += d;
                p.x += d * p.ux;
                p.y += d * p.uy;
                p.z = 0.0;
                let r = dielectric_reflectance(-p.uz, eta_out);
                if r >= 1.0 || uniform(rng) < r {
                    p.uz = -p.uz;
                    continue;
                }
                on_escape((p.x * p.x + p.y * p.y).sqrt(), path, &above);
                break;
            }
            add_above(&mut above, depths, p.z, z_new, s);
            path += s;
            p.x += s * p.ux;
            p.y += s * p.uy;
            p.z = z_new;
            if path > medium.max_path {
                dropped += 1;
                break;
            }
            scatter(&mut p, &hg, rng);
        }
    }
    dropped
}

/// Add to `above[t]` the part of a straight segment of length `len` from depth `za` to `zb` that
/// lies above `depths[t]` (the fraction of the depth range above it: z is linear along the segment).
#[inline(always)]
fn add_above(above: &mut [f64], depths: &[f64], za: f64, zb: f64, len: f64) {
    let (lo, hi) = if za < zb { (za, zb) } else { (zb, za) };
    // A horizontal segment gives ±∞ (all or nothing); `max` maps the 0·∞ NaN at τ = lo to 0.
    let inv = 1.0 / (hi - lo);
    for (a, &tau) in above.iter_mut().zip(depths) {
        *a += len * ((tau - lo) * inv).max(0.0).min(1.0);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn segment_split_at_a_depth() {
        let mut above = [0.0; 3];
        add_above(&mut above, &[0.5, 1.0, 3.0], 0.0, 2.0, 4.0);
        // z runs 0 → 2 over length 4: 1/4, 1/2 and all of it lie above depths 0.5, 1, 3.
        assert_eq!(above, [1.0, 2.0, 4.0]);
        let mut flat = [0.0; 2];
        add_above(&mut flat, &[0.5, 2.0], 1.0, 1.0, 3.0);
        assert_eq!(flat, [0.0, 3.0]);
    }

    #[test]
    fn paths_split_consistently_and_most_photons_escape() {
        let medium = WhiteMedium {
            g: 0.9,
            n: 1.4,
            max_path: 1.0e4,
        };
        let depths = [0.0, 5.0, 20.0, 1.0e9];
        let mut rng = Xoshiro256StarStar::seed_from_u64(3);
        let mut escapes = 0u64;
        let dropped = trace_white(&medium, &depths, 2_000, &mut rng, |r, path, above| {
            escapes += 1;
            // A path can never be shorter than the radius it reached; the part above a depth
            // grows with the depth, from 0 above z = 0 to the whole path above a depth no
            // history reaches.
            assert!(path >= r);
            assert_eq!(above[0], 0.0);
            assert!(above[1] <= above[2] && above[2] <= above[3]);
            assert!((above[3] - path).abs() <= 1e-9 * path);
        });
        assert_eq!(escapes + dropped, 2_000);
        // A white half-space returns every photon except those still inside at the path cap: the
        // fraction beyond 10⁴ scattering lengths (100 transport lengths at g = 0.9) is ~√(1/100) of
        // order 10%, so at least 80% escape.
        assert!(escapes >= 1_600, "{escapes}");
    }
}
