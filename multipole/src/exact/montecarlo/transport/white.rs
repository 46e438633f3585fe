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
    let mut split = DepthSplit::new(depths);
    let mut dropped = 0;
    for _ in 0..photons {
        let mut p = Photon::launched(1.0);
        split.clear();
        let mut path = 0.0;
        loop {
            let s: f64 = Exp1.sample(rng);
            let z_new = p.z + s * p.uz;
            if z_new < 0.0 {
                // Reaches the face. The unused depth is not carried: the exponential step is
                // memoryless, so a fresh draw after a reflection has the same distribution.
                let d = -p.z / p.uz;
                split.add(p.z, 0.0, d);
                path += d;
                p.x += d * p.ux;
                p.y += d * p.uy;
                p.z = 0.0;
                let r = dielectric_reflectance(-p.uz, eta_out);
                if r >= 1.0 || uniform(rng) < r {
                    p.uz = -p.uz;
                    continue;
                }
                on_escape((p.x * p.x + p.y * p.y).sqrt(), path, split.above());
                break;
            }
            split.add(p.z, z_new, s);
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

/// The part of a path above each of a sorted ladder of depths, accumulated segment by segment in
/// O(log depths) per segment: a segment wholly above the depths from index k on adds its length to
/// `from[k]` (summed over k at the end); only the depths it straddles get a partial length.
struct DepthSplit<'a> {
    depths: &'a [f64],
    from: Vec<f64>,
    partial: Vec<f64>,
    above: Vec<f64>,
}

impl<'a> DepthSplit<'a> {
    fn new(depths: &'a [f64]) -> Self {
        debug_assert!(depths.windows(2).all(|w| w[0] <= w[1]));
        Self {
            depths,
            from: vec![0.0; depths.len() + 1],
            partial: vec![0.0; depths.len()],
            above: vec![0.0; depths.len()],
        }
    }

    fn clear(&mut self) {
        self.from.fill(0.0);
        self.partial.fill(0.0);
    }

    /// A straight segment of length `len` from depth `za` to `zb`: z is linear along it, so the
    /// part above depth τ is len × (τ − lo)/(hi − lo) clamped to [0, 1].
    #[inline(always)]
    fn add(&mut self, za: f64, zb: f64, len: f64) {
        let (lo, hi) = if za < zb { (za, zb) } else { (zb, za) };
        let first = self.depths.partition_point(|&t| t <= lo);
        let full = first + self.depths[first..].partition_point(|&t| t < hi);
        self.from[full] += len;
        let inv = 1.0 / (hi - lo);
        for t in first..full {
            self.partial[t] += len * ((self.depths[t] - lo) * inv).clamp(0.0, 1.0);
        }
    }

    /// The path above each depth so far.
    fn above(&mut self) -> &[f64] {
        let mut run = 0.0;
        for t in 0..self.depths.len() {
            run += self.from[t];
            self.above[t] = run + self.partial[t];
        }
        &self.above
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn segment_split_at_a_depth() {
        let mut split = DepthSplit::new(&[0.5, 1.0, 3.0]);
        split.add(0.0, 2.0, 4.0);
        // z runs 0 → 2 over length 4: 1/4, 1/2 and all of it lie above depths 0.5, 1, 3.
        assert_eq!(split.above(), [1.0, 2.0, 4.0]);
        // Back up from 2 to 1.5 over length 1: above 3 only; then a horizontal move at z = 1
        // (neither above nor below depth 1: the depth test is z < τ, so it counts below).
        split.add(2.0, 1.5, 1.0);
        split.add(1.0, 1.0, 3.0);
        assert_eq!(split.above(), [1.0, 2.0, 8.0]);
        split.clear();
        split.add(0.7, 0.7, 2.0);
        assert_eq!(split.above(), [0.0, 2.0, 2.0]);
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
