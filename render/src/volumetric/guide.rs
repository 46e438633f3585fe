//! Guided sampling of the walk towards the surface (docs/physics.md §15.6): Dwivedi's
//! zero-variance-based sampling [KdE14, MHD16] of directions (pdf ∝ 1/(ν₀ − μ), μ the cosine to the
//! outward normal) and of free flights (rate σ̄ − μκ, longer towards the surface), mixed with
//! the classic sampling (isotropic phase, rate σ̄) by one-sample MIS with the balance heuristic
//! over each straight segment of the walk. The segment's weight is the classic pdf over the mixture's
//! (at most 1/(1 − f), f the guided fraction), so the walk stays unbiased for any medium: the guide
//! only moves where the samples go.

use glam::DVec3;
use multipole::exact::montecarlo::{HgSampler, scatter_direction};
use rand::{Rng, RngCore};
use std::f64::consts::PI;

/// Share of the walk's segments sampled by the guide (the rest classic), when the medium allows
/// guiding (BENCHMARKS.md, "Volumetric reference": the equal-noise efficiency of each value).
pub const DEFAULT_GUIDED_FRACTION: f64 = 0.8;

/// |g| below which scattering counts as isotropic (as `HgSampler` does), the only phase the
/// guide is used for.
pub const ISOTROPIC_BELOW: f64 = 1e-6;

/// How close 1/ν₀ may come to 1 (see [`dwivedi_nu0`]).
const NU0_ABOVE_ONE: f64 = 1e-12;

/// Dwivedi's ν₀ > 1 for single-scattering albedo `albedo` in (0, 1): the root of
/// α ν₀ artanh(1/ν₀) = 1, the decay length (in mean free paths) of the deep asymptotic radiance
/// e^(−z/ν₀) of an isotropically scattering half-space ([KdE14]; docs/physics.md §15.6).
/// `None` outside (0, 1) (no absorption: nothing decays).
#[must_use]
pub fn dwivedi_nu0(albedo: f64) -> Option<f64> {
    if !(albedo > 0.0 && albedo < 1.0) {
        return None;
    }
    // In u = 1/ν₀: φ(u) = artanh(u) − u/α is convex with φ(0) = 0, φ'(0) < 0; its positive root is
    // approached monotonically by Newton from any u where φ > 0, e.g. u₀ = √(3(1/α − 1)) (from
    // artanh(u)/u ≥ 1 + u²/3). Below α ≈ 0.1 the root lies closer to 1 than f64 resolves near
    // 1 − 10⁻¹²; ν₀ is then 1/(1 − 10⁻¹²).
    let mut u = (3.0 * (1.0 / albedo - 1.0)).sqrt().min(1.0 - NU0_ABOVE_ONE);
    if u.atanh() - u / albedo <= 0.0 {
        return Some(1.0 / u);
    }
    for _ in 0..100 {
        let phi = u.atanh() - u / albedo;
        let slope = 1.0 / (1.0 - u * u) - 1.0 / albedo;
        let next = u - phi / slope;
        if !(next > 0.0 && next < u) {
            break;
        }
        let done = u - next <= 1e-14 * u;
        u = next;
        if done {
            break;
        }
    }
    Some(1.0 / u)
}

/// Dwivedi's asymptotic mode of one layer: ν₀, the direction pdf's normalisation
/// ln((ν₀ + 1)/(ν₀ − 1)), and the decay rate κ = σt/ν₀ of the deep radiance, mm⁻¹.
#[derive(Debug, Clone, Copy)]
struct Mode {
    nu0: f64,
    log_ratio: f64,
    kappa: f64,
}

impl Mode {
    /// The mode of a layer of extinction `sigma_t` (mm⁻¹) and Dwivedi's `nu0` (> 1).
    fn new(sigma_t: f64, nu0: f64) -> Self {
        Self {
            nu0,
            log_ratio: ((nu0 + 1.0) / (nu0 - 1.0)).ln(),
            kappa: sigma_t / nu0,
        }
    }

    /// Guided direction pdf at cosine `mu` to the outward normal, sr⁻¹ ([MHD16] eq. 9).
    fn direction_pdf(&self, mu: f64) -> f64 {
        1.0 / (2.0 * PI * (self.nu0 - mu) * self.log_ratio)
    }
}

/// The guide of one walk: each layer's Dwivedi mode at the walk's wavelength, the majorant σ̄
/// (mm⁻¹) and the guided fraction.
#[derive(Debug, Clone, Copy)]
pub struct Guide {
    /// Per layer (epidermis, dermis), the mode its collisions are guided by.
    modes: [Mode; 2],
    majorant: f64,
    fraction: f64,
}

/// One straight segment of the walk, from a collision or a surface contact: how its flights are
/// sampled and what the MIS weight needs at its end.
#[derive(Debug, Clone, Copy)]
pub struct Segment {
    /// Rate of the tentative flights, mm⁻¹.
    pub rate: f64,
    /// Cosine of the direction to the guide's outward normal.
    mu: f64,
    /// κ of the mode guiding the segment, mm⁻¹.
    kappa: f64,
    /// Guided over classic direction pdf (1 when the direction was not sampled).
    direction_ratio: f64,
    /// Tentative collisions so far (null and real).
    flights: u32,
    /// Length flown so far, mm.
    length_mm: f64,
}

impl Segment {
    /// A classic segment (no guide): rate `majorant`.
    #[must_use]
    pub fn classic(majorant: f64) -> Self {
        Self {
            rate: majorant,
            mu: 0.0,
            kappa: 0.0,
            direction_ratio: 1.0,
            flights: 0,
            length_mm: 0.0,
        }
    }

    /// Record a tentative collision after `s_mm`.
    pub fn collide(&mut self, s_mm: f64) {
        self.flights += 1;
        self.length_mm += s_mm;
    }

    /// Record the last flight, `s_mm` to the surface.
    pub fn reach(&mut self, s_mm: f64) {
        self.length_mm += s_mm;
    }
}

/// The layer whose mode guides a segment.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Layer {
    /// The epidermis (and every segment starting on the surface).
    Epidermis,
    /// The dermis.
    Dermis,
}

impl Guide {
    /// The guide of a medium of majorant `majorant` (mm⁻¹) whose epidermis and dermis have
    /// (σa, σs) `layers` (mm⁻¹) and Dwivedi's ν₀ `nu0` (values ≤ 1: none, the layer does not
    /// absorb; [`dwivedi_nu0`], tabulated by the caller), with anisotropy `g`, sampling `fraction`
    /// of its segments; `None` when guiding does not apply (fraction 0, a clear medium, no
    /// absorption, or anisotropic scattering). A layer without ν₀ borrows the other's mode. Any ν₀
    /// > 1 gives an unbiased walk: the guide only moves the samples.
    #[must_use]
    pub fn new(
        majorant: f64,
        layers: [(f32, f32); 2],
        nu0: [f64; 2],
        g: f64,
        fraction: f64,
    ) -> Option<Self> {
        // Under Henyey–Greenstein scattering neither Dwivedi's directions (their mixture with a
        // peaked phase function gives weights of heavy tails) nor its flights alone paid
        // (BENCHMARKS.md, "Volumetric reference"): the walk stays classic there.
        if !(fraction > 0.0 && majorant > 0.0 && g.abs() < ISOTROPIC_BELOW) {
            return None;
        }
        let [e, d] = [0, 1].map(|i| {
            let (sa, ss) = layers[i];
            (nu0[i] > 1.0).then(|| Mode::new(f64::from(sa) + f64::from(ss), nu0[i]))
        });
        let modes = match (e, d) {
            (Some(e), Some(d)) => [e, d],
            (Some(m), None) | (None, Some(m)) => [m, m],
            (None, None) => return None,
        };
        Some(Self {
            modes,
            majorant,
            fraction,
        })
    }

    /// Dwivedi's ν₀ guiding collisions in `layer`.
    #[must_use]
    pub fn nu0(&self, layer: Layer) -> f64 {
        self.mode(layer).nu0
    }

    fn mode(&self, layer: Layer) -> &Mode {
        &self.modes[usize::from(layer == Layer::Dermis)]
    }

    /// A segment along `d` (unit) whose direction was given, not sampled (the entry's refraction, a
    /// reflection at the surface): the guide or the classic rate is drawn for its flights.
    pub fn along<R: RngCore>(&self, d: DVec3, normal: DVec3, rng: &mut R) -> Segment {
        let mu = d.dot(normal).clamp(-1.0, 1.0);
        let mode = self.mode(Layer::Epidermis);
        self.segment(mode, mu, 1.0, rng.random::<f64>() < self.fraction)
    }

    /// A new direction after a real collision in `layer` at direction `d` (unit), from the guide
    /// (towards `normal`, the outward normal) or from the (isotropic) phase function, and its
    /// segment.
    pub fn scatter<R: RngCore>(
        &self,
        layer: Layer,
        d: DVec3,
        normal: DVec3,
        hg: &HgSampler,
        rng: &mut R,
    ) -> (DVec3, Segment) {
        let mode = self.mode(layer);
        let guided = rng.random::<f64>() < self.fraction;
        let next = if guided {
            // Inverse CDF of 1/(ν₀ − μ) on [−1, 1] ([MHD16] eq. 10).
            let xi = rng.random::<f64>();
            let mu = (mode.nu0 - (mode.nu0 + 1.0) * (-xi * mode.log_ratio).exp()).clamp(-1.0, 1.0);
            let phi = 2.0 * PI * rng.random::<f64>();
            let (t, b) = normal.any_orthonormal_pair();
            let sin = (1.0 - mu * mu).max(0.0).sqrt();
            (t * (sin * phi.cos()) + b * (sin * phi.sin()) + normal * mu).normalize()
        } else {
            DVec3::from_array(scatter_direction(d.to_array(), hg, rng)).normalize()
        };
        let mu = next.dot(normal).clamp(-1.0, 1.0);
        // Over the isotropic phase function's 1/(4π).
        let ratio = mode.direction_pdf(mu) * 4.0 * PI;
        (next, self.segment(mode, mu, ratio, guided))
    }

    fn segment(&self, mode: &Mode, mu: f64, direction_ratio: f64, guided: bool) -> Segment {
        Segment {
            rate: if guided {
                self.majorant - mu * mode.kappa
            } else {
                self.majorant
            },
            mu,
            kappa: mode.kappa,
            direction_ratio,
            flights: 0,
            length_mm: 0.0,
        }
    }

    /// The weight of a finished segment: its classic pdf over the mixture's,
    /// 1 / ((1 − f) + f · p_g/p_c), with p_g/p_c = (pdf ratio of the direction) ·
    /// ((σ̄ − μκ)/σ̄)ⁿ · exp(μκL) over its n tentative collisions and length L (the null/real
    /// choices and the surface's are the same in both, and cancel). The guided rate σ̄ − μκ
    /// ([KdE14]: σt(1 − μ/ν₀) in a homogeneous medium) is > 0 since κ < σt ≤ σ̄.
    #[must_use]
    pub fn weight(&self, s: &Segment) -> f64 {
        let stretch = 1.0 - s.mu * s.kappa / self.majorant;
        let log_ratio = s.direction_ratio.ln()
            + f64::from(s.flights) * stretch.ln()
            + s.mu * s.kappa * s.length_mm;
        1.0 / ((1.0 - self.fraction) + self.fraction * log_ratio.exp())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_xoshiro::Xoshiro256PlusPlus;

    /// ν₀ solves α ν₀ artanh(1/ν₀) = 1 to 1e-10 (artanh near 1 amplifies the rounding of 1/ν₀), and meets its limits: ν₀ → 1 as α → 0 (at
    /// α = 0.01 the root is 1 + 10⁻⁸⁶, held at 1 + 10⁻¹²) and
    /// ν₀ ≈ 1/√(3(1 − α)) as α → 1 (the diffusion length; within 0.1% at α = 0.9999); the
    /// tabulated ν₀(0.9) = 1.9032 of Case & Zweifel (within 1e-4).
    #[test]
    fn nu0_solves_the_dispersion_relation() {
        for albedo in [0.15, 0.3, 0.7, 0.9, 0.99, 0.9999] {
            let nu = dwivedi_nu0(albedo).unwrap();
            let residual = albedo * nu * (1.0 / nu).atanh() - 1.0;
            assert!(residual.abs() < 1e-10, "α {albedo}: residual {residual}");
        }
        assert!((dwivedi_nu0(0.01).unwrap() - 1.0).abs() < 1e-11);
        let nu = dwivedi_nu0(0.9999).unwrap();
        let diffusion = 1.0 / (3.0f64 * 1e-4).sqrt();
        assert!((nu / diffusion - 1.0).abs() < 1e-3, "{nu} vs {diffusion}");
        assert!((dwivedi_nu0(0.9).unwrap() - 1.9032).abs() < 1e-4);
        assert!(dwivedi_nu0(1.0).is_none() && dwivedi_nu0(0.0).is_none());
    }

    /// The guided directions follow 1/(ν₀ − μ): their mean cosine to the normal equals the closed
    /// form ν₀ − 2/ln((ν₀+1)/(ν₀−1)) within 4 standard errors, and the pdf integrates to 1.
    #[test]
    fn guided_directions_follow_dwivedi() {
        let nu = dwivedi_nu0(0.9).unwrap();
        let guide = Guide::new(10.0, [(1.0, 9.0), (1.0, 9.0)], [nu; 2], 0.0, 1.0).unwrap();
        let normal = DVec3::new(0.3, -0.4, 0.5).normalize();
        let hg = HgSampler::new(0.0);
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(3);
        let n = 200_000;
        let (mut sum, mut sum2) = (0.0, 0.0);
        for _ in 0..n {
            let (d, _) = guide.scatter(Layer::Dermis, DVec3::X, normal, &hg, &mut rng);
            let mu = d.dot(normal);
            sum += mu;
            sum2 += mu * mu;
        }
        let mean = sum / f64::from(n);
        let se = ((sum2 / f64::from(n) - mean * mean) / f64::from(n)).sqrt();
        let mode = guide.mode(Layer::Dermis);
        let want = mode.nu0 - 2.0 / mode.log_ratio;
        assert!((mean - want).abs() < 4.0 * se, "{mean} ± {se} vs {want}");
        // Midpoint rule over μ of 2π p(μ): ∫ p dω = 1.
        let m = 100_000;
        let total: f64 = (0..m)
            .map(|i| {
                let mu = -1.0 + (f64::from(i) + 0.5) * 2.0 / f64::from(m);
                2.0 * PI * mode.direction_pdf(mu) * 2.0 / f64::from(m)
            })
            .sum();
        assert!((total - 1.0).abs() < 1e-6, "{total}");
    }

    /// The segment weight is exact: the weighted chance of crossing a homogeneous layer of
    /// thickness L along a fixed direction, flights drawn from the mixture and each tentative
    /// collision null with probability p (the walk flies on along the same segment), is the
    /// transmittance exp(−σ̄(1 − p)L) — for directions towards and away from the surface, pure
    /// classic (f 0), mixed (f 0.8) and pure guided (f 1); within 4 standard errors.
    #[test]
    fn segment_weights_keep_the_transmittance() {
        let normal = DVec3::Z;
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(17);
        let (majorant, length) = (5.0, 0.4);
        for fraction in [0.0, 0.8, 1.0] {
            // One layer of albedo 0.8, and a null share of 0.3.
            let nu = dwivedi_nu0(0.8).unwrap();
            let guide = Guide::new(majorant, [(1.0, 4.0), (1.0, 4.0)], [nu; 2], 0.0, fraction);
            for mu in [-0.8f64, 0.3, 0.95] {
                let d = DVec3::new((1.0f64 - mu * mu).sqrt(), 0.0, mu);
                let null = 0.3;
                let n = 100_000;
                let (mut sum, mut sum2) = (0.0, 0.0);
                for _ in 0..n {
                    let mut seg = match &guide {
                        Some(g) => g.along(d, normal, &mut rng),
                        None => Segment::classic(majorant),
                    };
                    let mut left = length;
                    let w = loop {
                        let s = -(1.0 - rng.random::<f64>()).ln() / seg.rate;
                        if s >= left {
                            seg.reach(left);
                            break guide.as_ref().map_or(1.0, |g| g.weight(&seg));
                        }
                        left -= s;
                        seg.collide(s);
                        if rng.random::<f64>() >= null {
                            break 0.0;
                        }
                    };
                    sum += w;
                    sum2 += w * w;
                }
                let mean = sum / f64::from(n);
                let se = ((sum2 / f64::from(n) - mean * mean) / f64::from(n)).sqrt();
                let want = (-majorant * (1.0 - null) * length).exp();
                assert!(
                    (mean - want).abs() < 4.0 * se,
                    "f {fraction}, μ {mu}: {mean} ± {se} vs {want}"
                );
            }
        }
        // Anisotropic scattering is not guided.
        assert!(Guide::new(majorant, [(1.0, 4.0), (1.0, 4.0)], [2.0; 2], 0.9, 0.8).is_none());
    }
}
