//! One texel's inversion on a [`Slice`]: a seed from a lookup grid over CIELAB, then damped
//! Gauss–Newton (Levenberg–Marquardt) steps in CIELAB on the slice's bicubic interpolant
//! (docs/physics.md §18).

use super::table::Slice;

/// Lower corner of the seed grid in CIELAB (L*, a*, b*).
const SEED_MIN: [f64; 3] = [0.0, -30.0, -30.0];
/// Seed-grid spacing along L*, a*, b* (ΔE76 units).
const SEED_STEP: [f64; 3] = [4.0, 5.0, 5.0];
/// Seed-grid nodes along L*, a*, b*.
const SEED_NODES: [usize; 3] = [26, 21, 21];
/// Forward samples per unit-coordinate axis that the seed grid picks its starts from.
const SEED_SAMPLES: [usize; 2] = [49, 33];

/// ΔE charged per unit of v away from its middle (C_h = 0.01): the prior that decides C_h where
/// the colour cannot (much melanin hides the dermis); the value of `skin fit`'s colour prior.
pub const PRIOR_WEIGHT_DE: f64 = 0.01;

/// Most interpolant evaluations per texel.
const MAX_EVALS: usize = 12;

/// A slice with its seed grid.
#[derive(Debug, Clone)]
pub struct Inverter {
    slice: Slice,
    seeds: Vec<[f32; 2]>,
}

/// One texel's result: unit coordinates and the slice's colour there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Inverted {
    /// Unit melanin coordinate u.
    pub u: f64,
    /// Unit hemoglobin coordinate v.
    pub v: f64,
    /// CIELAB of the fitted skin on the slice.
    pub lab: [f64; 3],
}

impl Inverter {
    /// The seed grid of `slice`: every node takes the forward sample nearest to it in CIELAB.
    #[must_use]
    pub fn new(slice: Slice) -> Self {
        let samples: Vec<([f64; 3], [f32; 2])> = (0..SEED_SAMPLES[1])
            .flat_map(|j| (0..SEED_SAMPLES[0]).map(move |i| (i, j)))
            .map(|(i, j)| {
                let u = i as f64 / (SEED_SAMPLES[0] - 1) as f64;
                let v = j as f64 / (SEED_SAMPLES[1] - 1) as f64;
                (slice.lab(u, v), [u as f32, v as f32])
            })
            .collect();
        let [nl, na, nb] = SEED_NODES;
        let seeds = (0..nl * na * nb)
            .map(|k| {
                let node = [k % nl, (k / nl) % na, k / (nl * na)];
                let lab: [f64; 3] =
                    std::array::from_fn(|c| SEED_MIN[c] + SEED_STEP[c] * node[c] as f64);
                samples
                    .iter()
                    .map(|(s, uv)| (dist2(s, &lab), *uv))
                    .min_by(|a, b| a.0.total_cmp(&b.0))
                    .map_or([0.5, 0.5], |(_, uv)| uv)
            })
            .collect();
        Self { slice, seeds }
    }

    /// The slice inverted.
    #[must_use]
    pub fn slice(&self) -> &Slice {
        &self.slice
    }

    fn seed(&self, lab: &[f64; 3]) -> [f64; 2] {
        let [nl, na, _] = SEED_NODES;
        let idx: [usize; 3] = std::array::from_fn(|c| {
            let x = ((lab[c] - SEED_MIN[c]) / SEED_STEP[c]).round();
            x.clamp(0.0, (SEED_NODES[c] - 1) as f64) as usize
        });
        let s = self.seeds[(idx[2] * na + idx[1]) * nl + idx[0]];
        [f64::from(s[0]), f64::from(s[1])]
    }

    /// The skin on the slice nearest to `target` (CIELAB, finite) in ΔE76 plus the C_h prior.
    #[must_use]
    pub fn invert(&self, target: &[f64; 3]) -> Inverted {
        let [mut u, mut v] = self.seed(target);
        let cost =
            |lab: &[f64; 3], v: f64| dist2(lab, target) + (PRIOR_WEIGHT_DE * (v - 0.5)).powi(2);
        let (mut f, mut fu, mut fv) = self.slice.lab_and_gradient(u, v);
        let mut c = cost(&f, v);
        let mut lambda = 1e-3;
        let mut evals = 1;
        while evals < MAX_EVALS {
            // Normal equations of the 3 colour residuals and the prior's.
            let r: [f64; 3] = std::array::from_fn(|k| f[k] - target[k]);
            let pr = PRIOR_WEIGHT_DE * (v - 0.5);
            let a11 = dot(&fu, &fu);
            let a12 = dot(&fu, &fv);
            let a22 = dot(&fv, &fv) + PRIOR_WEIGHT_DE * PRIOR_WEIGHT_DE;
            let g1 = dot(&fu, &r);
            let g2 = dot(&fv, &r) + PRIOR_WEIGHT_DE * pr;
            let mut accepted = false;
            while evals < MAX_EVALS {
                let (d11, d22) = (a11 * (1.0 + lambda) + 1e-12, a22 * (1.0 + lambda) + 1e-12);
                let det = d11 * d22 - a12 * a12;
                if det.is_finite() && det <= 0.0 {
                    lambda *= 10.0;
                    continue;
                }
                let du = -(d22 * g1 - a12 * g2) / det;
                let dv = -(d11 * g2 - a12 * g1) / det;
                let (nu, nv) = ((u + du).clamp(0.0, 1.0), (v + dv).clamp(0.0, 1.0));
                let (nf, nfu, nfv) = self.slice.lab_and_gradient(nu, nv);
                evals += 1;
                let nc = cost(&nf, nv);
                if nc <= c {
                    let moved = (nu - u).abs().max((nv - v).abs());
                    (u, v, f, fu, fv) = (nu, nv, nf, nfu, nfv);
                    let gain = c - nc;
                    c = nc;
                    lambda = (lambda * 0.1).max(1e-9);
                    accepted = true;
                    if moved < 1e-6 || gain < 1e-10 {
                        return Inverted { u, v, lab: f };
                    }
                    break;
                }
                lambda *= 10.0;
                if lambda > 1e8 {
                    break;
                }
            }
            if !accepted {
                break;
            }
        }
        Inverted { u, v, lab: f }
    }
}

#[inline]
fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline]
fn dist2(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    dot(&d, &d)
}
