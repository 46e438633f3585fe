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

/// Lower corner of the inverse lookup grid in CIELAB (the seed grid's box).
const LOOKUP_MIN: [f64; 3] = SEED_MIN;
/// Inverse-lookup spacing along L*, a*, b* (ΔE76 units).
const LOOKUP_STEP: [f64; 3] = [1.0, 1.25, 1.25];
/// Inverse-lookup nodes along L*, a*, b* (covering L* 0–100, a* and b* −30–70).
const LOOKUP_SHAPE: [usize; 3] = [101, 81, 81];
/// Nodes of the inverse lookup grid.
pub const LOOKUP_NODES: usize = LOOKUP_SHAPE[0] * LOOKUP_SHAPE[1] * LOOKUP_SHAPE[2];

/// A slice with its seed grid and, for whole textures, its inverse lookup grid.
#[derive(Debug, Clone)]
pub struct Inverter {
    slice: Slice,
    seeds: Vec<[f32; 2]>,
    /// The full inversion's (u, v) at every node of a grid over CIELAB.
    lookup: Vec<[f32; 2]>,
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
        Self {
            slice,
            seeds,
            lookup: Vec::new(),
        }
    }

    /// [`Inverter::new`] plus the inverse lookup grid that [`Inverter::invert_fast`] reads: the
    /// full inversion ([`Inverter::invert`]) at every node ([`LOOKUP_NODES`], on rayon's
    /// threads).
    #[must_use]
    pub fn with_lookup(slice: Slice) -> Self {
        use rayon::prelude::*;
        let mut inv = Self::new(slice);
        let [nl, na, nb] = LOOKUP_SHAPE;
        inv.lookup = (0..nl * na * nb)
            .into_par_iter()
            .with_min_len(1024)
            .map(|k| {
                let node = [k % nl, (k / nl) % na, k / (nl * na)];
                let lab: [f64; 3] =
                    std::array::from_fn(|c| LOOKUP_MIN[c] + LOOKUP_STEP[c] * node[c] as f64);
                let r = inv.invert(&lab);
                [r.u as f32, r.v as f32]
            })
            .collect();
        inv
    }

    /// The inversion of `target` from the inverse lookup grid (trilinear in CIELAB, clamped to
    /// the grid's box) and one Gauss–Newton step on the slice, kept only if it lowers the cost.
    /// Falls back to [`Inverter::invert`] without the grid.
    #[must_use]
    pub fn invert_fast(&self, target: &[f64; 3]) -> Inverted {
        if self.lookup.is_empty() {
            return self.invert(target);
        }
        let [nl, na, _] = LOOKUP_SHAPE;
        let mut base = [0usize; 3];
        let mut frac = [0.0f64; 3];
        for c in 0..3 {
            let x = ((target[c] - LOOKUP_MIN[c]) / LOOKUP_STEP[c])
                .clamp(0.0, (LOOKUP_SHAPE[c] - 1) as f64);
            let i = (x as usize).min(LOOKUP_SHAPE[c] - 2);
            base[c] = i;
            frac[c] = x - i as f64;
        }
        // Trilinear: along L* within each of the four (a*, b*) corner pairs, then a*, then b*.
        let at = |da: usize, db: usize| -> [f64; 2] {
            let k = (base[2] + db) * na * nl + (base[1] + da) * nl + base[0];
            let (p, q) = (self.lookup[k], self.lookup[k + 1]);
            let t = frac[0];
            [
                f64::from(p[0]) + t * (f64::from(q[0]) - f64::from(p[0])),
                f64::from(p[1]) + t * (f64::from(q[1]) - f64::from(p[1])),
            ]
        };
        let lerp =
            |p: [f64; 2], q: [f64; 2], t: f64| [p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])];
        let near = lerp(at(0, 0), at(1, 0), frac[1]);
        let far = lerp(at(0, 1), at(1, 1), frac[1]);
        let [u, v] = lerp(near, far, frac[2]);
        let (f, fu, fv) = self.slice.lab_and_gradient(u, v);
        let r: [f64; 3] = std::array::from_fn(|k| f[k] - target[k]);
        let a11 = dot(&fu, &fu) + 1e-12;
        let a12 = dot(&fu, &fv);
        let a22 = dot(&fv, &fv) + PRIOR_WEIGHT_DE * PRIOR_WEIGHT_DE + 1e-12;
        let g1 = dot(&fu, &r);
        let g2 = dot(&fv, &r) + PRIOR_WEIGHT_DE * PRIOR_WEIGHT_DE * (v - 0.5);
        let det = a11 * a22 - a12 * a12;
        let cost =
            |lab: &[f64; 3], v: f64| dist2(lab, target) + (PRIOR_WEIGHT_DE * (v - 0.5)).powi(2);
        if det > 0.0 {
            let nu = (u - (a22 * g1 - a12 * g2) / det).clamp(0.0, 1.0);
            let nv = (v - (a11 * g2 - a12 * g1) / det).clamp(0.0, 1.0);
            let nf = self.slice.lab(nu, nv);
            if cost(&nf, nv) < cost(&f, v) {
                return Inverted {
                    u: nu,
                    v: nv,
                    lab: nf,
                };
            }
        }
        Inverted { u, v, lab: f }
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
