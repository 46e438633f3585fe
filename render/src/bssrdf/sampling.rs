//! Exit-point sampling with probe rays ([KHPC13], pbrt-v3/v4; docs/physics.md §8).
//!
//! Pick an axis of the shading frame at the entry point (normal with probability p, by default ½,
//! each tangent (1 − p)/2), a radius r
//! from the hero wavelength's 2πr R(r) / R_tot and φ uniform; the probe is the segment of
//! half-length ℓ = √(r_max² − r²) along the axis through p_o + r (cos φ b₁ + sin φ b₂), where b₁, b₂
//! span the plane perpendicular to the axis. Every point within distance r_max of p_o can be reached
//! through each axis, so the one-sample MIS density of a found point p_i with normal n_i is
//!
//! pdf(p_i) = Σ_a P(a) · pdf_area(r_a) · |n_i · a|,   r_a = distance from p_o to p_i projected ⊥ a,
//!
//! per unit area (pdf_area = R(r)/R_tot per mm², [`super::ProfileTable::pdf_area`]). For spectral
//! rendering the same formula with each wavelength's profile gives one density per wavelength.

use glam::Vec3;

/// Probability of choosing the normal axis in pbrt-v3/v4 (the tangents share the rest equally).
pub const P_NORMAL_AXIS: f32 = 0.5;

/// Probability of the normal axis in the renderer: of 0.5, 0.8, 0.9 and 0.95, 0.95 gave the least
/// noise at equal CPU time on the default scene and on the backlit ear (BENCHMARKS.md, "Image
/// noise"): on skin that is flat within the profile's reach a tangent probe finds nothing.
pub const RENDER_P_NORMAL_AXIS: f32 = 0.95;

/// How probe axes are chosen: the normal with probability `p_normal`, each tangent with
/// (1 − p_normal)/2. On flat skin only normal probes find the surface, so a larger `p_normal`
/// wastes fewer probes there; the tangents are what find curved and thin skin (any p_normal < 1
/// keeps every exit point reachable, and the MIS density stays exact).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProbeAxes {
    probability: [f32; 3],
}

impl Default for ProbeAxes {
    fn default() -> Self {
        Self::DEFAULT
    }
}

impl ProbeAxes {
    /// The normal with [`RENDER_P_NORMAL_AXIS`]: what renders use.
    pub const DEFAULT: Self = Self::constant(RENDER_P_NORMAL_AXIS);
    /// The normal with [`P_NORMAL_AXIS`] (pbrt's choice).
    pub const PBRT: Self = Self::constant(P_NORMAL_AXIS);

    const fn constant(p: f32) -> Self {
        Self {
            probability: [p, 0.5 * (1.0 - p), 0.5 * (1.0 - p)],
        }
    }

    /// Axes with the normal chosen with probability `p_normal` in (0, 1) (None outside).
    #[must_use]
    pub fn new(p_normal: f32) -> Option<Self> {
        (p_normal > 0.0 && p_normal < 1.0).then_some(Self {
            probability: [p_normal, 0.5 * (1.0 - p_normal), 0.5 * (1.0 - p_normal)],
        })
    }

    /// Probabilities of the normal, the first and the second tangent.
    #[must_use]
    pub fn probabilities(&self) -> [f32; 3] {
        self.probability
    }

    /// Probability of the normal axis.
    #[must_use]
    pub fn p_normal(&self) -> f32 {
        self.probability[0]
    }

    /// Choose an axis from `u` in [0, 1), returning it and `u` remapped to [0, 1).
    #[must_use]
    pub fn choose(&self, u: f32) -> (usize, f32) {
        let mut acc = 0.0;
        for (a, &p) in self.probability.iter().enumerate() {
            if u < acc + p || a == 2 {
                return (a, ((u - acc) / p).clamp(0.0, 1.0 - f32::EPSILON));
            }
            acc += p;
        }
        unreachable!("the loop returns at a == 2")
    }
}

/// How the wavelength whose profile draws a probe's radius is chosen among a path's wavelengths:
/// lane j with probability c_j = s / n + (1 − s) w_j / Σ w, n the active lanes, w_j the lane's
/// share of the pixel's luminance (ȳ(λ_j) / p(λ_j) · R_tot(λ_j)) and s the uniform share. The exit
/// density is then the mixture Σ c_j pdf_j (one-sample MIS, balance heuristic; docs/physics.md §8):
/// at s = 0 the luminance of the spatial weight, Σ_k w_k R_k(r) / Σ_j c_j pdf_j(r), is the same
/// constant at every radius, so a pixel's luminance keeps only the variance of the light at the
/// exit points. Any s > 0 keeps every lane's profile reachable.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RadiusWavelength {
    uniform_share: f32,
}

impl Default for RadiusWavelength {
    fn default() -> Self {
        Self::RENDER
    }
}

impl RadiusWavelength {
    /// Every lane alike (the hero's profile, as in pbrt-v4: the hero is any lane with equal chance).
    pub const HERO: Self = Self { uniform_share: 1.0 };
    /// The renderer's default uniform share, [`RENDER_UNIFORM_SHARE`].
    pub const RENDER: Self = Self {
        uniform_share: RENDER_UNIFORM_SHARE,
    };

    /// The choice with uniform share `s` in (0, 1] (None outside).
    #[must_use]
    pub const fn new(s: f32) -> Option<Self> {
        if s > 0.0 && s <= 1.0 {
            Some(Self { uniform_share: s })
        } else {
            None
        }
    }

    /// The uniform share s.
    #[must_use]
    pub fn uniform_share(&self) -> f32 {
        self.uniform_share
    }

    /// The lane probabilities c_j from the lanes' luminance weights (`None` for an inactive lane):
    /// uniform over the active lanes when the weights sum to 0 or are not finite.
    #[must_use]
    pub fn probabilities<const N: usize>(&self, weights: [Option<f32>; N]) -> [f32; N] {
        let n = weights.iter().flatten().count();
        if n == 0 {
            return [0.0; N];
        }
        let total: f32 = weights.iter().flatten().sum();
        let s = if total > 0.0 && total.is_finite() {
            self.uniform_share
        } else {
            1.0
        };
        weights.map(|w| {
            w.map_or(0.0, |w| {
                let lum = if s < 1.0 { w / total } else { 0.0 };
                s / n as f32 + (1.0 - s) * lum
            })
        })
    }

    /// The lane chosen by `u` in [0, 1) from probabilities `c` (the last active lane for u → 1).
    #[must_use]
    pub fn choose<const N: usize>(c: &[f32; N], u: f32) -> usize {
        let mut acc = 0.0;
        let mut last = 0;
        for (j, &p) in c.iter().enumerate() {
            if p > 0.0 {
                acc += p;
                last = j;
                if u < acc {
                    return j;
                }
            }
        }
        last
    }
}

/// Uniform share of the renderer's radius-wavelength choice ([`RadiusWavelength`]): of the shares
/// measured on the default scene, the one with the least luminance noise on skin at equal CPU time
/// (docs/benchmarks-archive.md, "Image noise: the radius wavelength").
pub const RENDER_UNIFORM_SHARE: f32 = 0.1;

/// An orthonormal shading frame at the entry point (world space; `n` = outward normal).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProbeFrame {
    /// First tangent.
    pub x: Vec3,
    /// Second tangent.
    pub y: Vec3,
    /// Normal.
    pub n: Vec3,
}

impl ProbeFrame {
    /// The three axes in the order of [`ProbeAxes::probabilities`]: normal, x, y.
    #[must_use]
    pub fn axes(&self) -> [Vec3; 3] {
        [self.n, self.x, self.y]
    }

    /// The two unit vectors spanning the plane perpendicular to axis `a` (index into `axes`).
    fn plane_of(&self, a: usize) -> (Vec3, Vec3) {
        match a {
            0 => (self.x, self.y),
            1 => (self.y, self.n),
            _ => (self.n, self.x),
        }
    }
}

/// A probe segment: from `origin` along unit `dir` for `length` mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Probe {
    /// Axis index (0 normal, 1 and 2 tangents).
    pub axis: usize,
    /// Sampled radius, mm.
    pub r_mm: f32,
    /// Segment start, mm.
    pub origin: Vec3,
    /// Unit direction (minus the axis).
    pub dir: Vec3,
    /// Segment length, mm.
    pub length: f32,
}

/// The probe for entry point `p_o`, axis `axis`, radius `r_mm` ≤ `r_max_mm`, angle from `u_phi`.
#[must_use]
pub fn probe(
    frame: &ProbeFrame,
    p_o: Vec3,
    axis: usize,
    r_mm: f32,
    r_max_mm: f32,
    u_phi: f32,
) -> Probe {
    let phi = 2.0 * std::f32::consts::PI * u_phi;
    let (b1, b2) = frame.plane_of(axis);
    let a = frame.axes()[axis];
    // A tiny floor keeps probes at r ≈ r_max from degenerating to zero length (which would miss a
    // plane through p_o); beyond r_max the profile is 0, so a longer segment adds nothing.
    let half = (r_max_mm * r_max_mm - r_mm * r_mm)
        .max(0.0)
        .sqrt()
        .max(1e-3 * r_max_mm);
    let centre = p_o + (b1 * phi.cos() + b2 * phi.sin()) * r_mm;
    // `+ 0.0` turns −0.0 components into +0.0: obvhs 0.4's CWBVH traversal misses with
    // axis-aligned directions holding −0.0 (the octant of 1/−0 = −∞; found by the slab χ² test).
    Probe {
        axis,
        r_mm,
        origin: centre + a * half,
        dir: -a + Vec3::ZERO,
        length: 2.0 * half,
    }
}

/// One-sample MIS density (per mm²) of finding `p_i` (normal `n_i`) from `p_o` with axes chosen
/// by `axes`, given the per-area radial density `pdf_area(r)` of one wavelength.
#[must_use]
pub fn pdf_exit(
    axes: &ProbeAxes,
    frame: &ProbeFrame,
    p_o: Vec3,
    p_i: Vec3,
    n_i: Vec3,
    pdf_area: impl Fn(f32) -> f32,
) -> f32 {
    let d = p_i - p_o;
    frame
        .axes()
        .iter()
        .zip(axes.probabilities())
        .map(|(&a, p)| {
            let along = d.dot(a);
            let r_a = (d.length_squared() - along * along).max(0.0).sqrt();
            p * pdf_area(r_a) * n_i.dot(a).abs()
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axis_choice_has_the_documented_probabilities() {
        let n = 100_000;
        for axes in [ProbeAxes::PBRT, ProbeAxes::new(0.8).unwrap()] {
            let mut count = [0usize; 3];
            for i in 0..n {
                let (a, v) = axes.choose((i as f32 + 0.5) / n as f32);
                assert!((0.0..1.0).contains(&v));
                count[a] += 1;
            }
            for (c, p) in count.iter().zip(axes.probabilities()) {
                assert!((*c as f32 / n as f32 - p).abs() < 1e-3, "{count:?}");
            }
        }
        assert!(ProbeAxes::new(1.0).is_none() && ProbeAxes::new(0.0).is_none());
    }

    /// The probe passes through the sampled point in the plane ⊥ axis, and stays within r_max.
    #[test]
    fn probe_geometry() {
        let f = ProbeFrame {
            x: Vec3::X,
            y: Vec3::Y,
            n: Vec3::Z,
        };
        let p = probe(&f, Vec3::ZERO, 0, 0.6, 1.0, 0.125);
        assert!((p.length - 1.6).abs() < 1e-5);
        let end = p.origin + p.dir * p.length;
        assert!((p.origin.length() - 1.0).abs() < 1e-5 && (end.length() - 1.0).abs() < 1e-5);
        let mid = p.origin + p.dir * (0.5 * p.length);
        assert!((mid.z).abs() < 1e-6 && (mid.truncate().length() - 0.6).abs() < 1e-5);
    }

    /// On a plane, only the normal axis finds points: the density is ½ pdf_area, and it integrates
    /// to ½ over the plane for any normalised radial density (here R ∝ e^{−r}/r).
    #[test]
    fn exit_pdf_on_a_plane_integrates_to_the_normal_axis_share() {
        let f = ProbeFrame {
            x: Vec3::X,
            y: Vec3::Y,
            n: Vec3::Z,
        };
        let pdf_area = |r: f32| (-r).exp() / (2.0 * std::f32::consts::PI * r.max(1e-9));
        let n = 200_000;
        let r_max = 30.0f32;
        let h = r_max / n as f32;
        let s: f64 = (0..n)
            .map(|i| {
                let r = (i as f32 + 0.5) * h;
                let p = pdf_exit(
                    &ProbeAxes::PBRT,
                    &f,
                    Vec3::ZERO,
                    Vec3::new(r, 0.0, 0.0),
                    Vec3::Z,
                    pdf_area,
                );
                f64::from(p * 2.0 * std::f32::consts::PI * r * h)
            })
            .sum();
        assert!((s - 0.5).abs() < 1e-4, "∫ pdf dA = {s}");
    }
}
