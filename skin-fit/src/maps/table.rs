//! The forward table of the maps inversion: the exact model's colour (CIELAB, D65) on a grid over
//! (C_m, β_m, C_h), and its slice at one β_m, a bicubic interpolant with derivatives
//! (docs/physics.md §18).
//!
//! Nodes are spaced evenly in two unit coordinates where colour changes roughly evenly:
//! u = ln(1 + C_m / c₀) / ln(1 + C_max / c₀) with the knee c₀ = [`MELANIN_KNEE`] (logarithmic
//! above the knee, linear through C_m = 0), and v = log(C_h / C_lo) / log(C_hi / C_lo) over the
//! table's C_h range [C_lo, C_hi] ([`HEMOGLOBIN_RANGE`], [0.001, 0.1], unless built over another).
//! Every node is one call of the exact forward model, the same path as `skin spectrum` and
//! `skin fit` ([`crate::ColourModel`]: adding-doubling diffuse reflectance over 400–700 nm every
//! 10 nm, CIE 1931 2°, D65).

use crate::forward::Forward;
use crate::{ColourModel, FitError, HEMOGLOBIN_RANGE, MELANIN_RANGE};
use multipole::exact::adding_doubling::AddingDoublingOptions;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use skin_optics::SkinParams;

/// Melanin knee c₀ of the u axis: below it the axis is linear in C_m, above it logarithmic.
pub const MELANIN_KNEE: f64 = 0.005;

/// The wavelength step of the colour behind every node, nm (the default of `skin fit` and of
/// `skin spectrum`).
pub const STEP_NM: f64 = 10.0;

/// C_m of the unit coordinate u ∈ [0, 1].
#[must_use]
pub fn melanin_of_u(u: f64) -> f64 {
    let span = (MELANIN_RANGE[1] / MELANIN_KNEE).ln_1p();
    (MELANIN_KNEE * (u * span).exp_m1()).clamp(MELANIN_RANGE[0], MELANIN_RANGE[1])
}

/// The unit coordinate u of C_m (inverse of [`melanin_of_u`]).
#[must_use]
pub fn u_of_melanin(c_m: f64) -> f64 {
    let span = (MELANIN_RANGE[1] / MELANIN_KNEE).ln_1p();
    ((c_m.max(0.0) / MELANIN_KNEE).ln_1p() / span).clamp(0.0, 1.0)
}

/// C_h of the unit coordinate v ∈ [0, 1] on the default axis over [`HEMOGLOBIN_RANGE`].
#[must_use]
pub fn hemoglobin_of_v(v: f64) -> f64 {
    hemoglobin_of_v_over(v, HEMOGLOBIN_RANGE)
}

/// The unit coordinate v of C_h on the default axis (inverse of [`hemoglobin_of_v`]).
#[must_use]
pub fn v_of_hemoglobin(c_h: f64) -> f64 {
    v_of_hemoglobin_over(c_h, HEMOGLOBIN_RANGE)
}

/// C_h of the unit coordinate v ∈ [0, 1] on the logarithmic axis over `range` = [C_lo, C_hi].
#[must_use]
pub fn hemoglobin_of_v_over(v: f64, range: [f64; 2]) -> f64 {
    let [lo, hi] = range;
    (lo * (hi / lo).powf(v)).clamp(lo, hi)
}

/// The unit coordinate v of C_h on the axis over `range` (inverse of [`hemoglobin_of_v_over`]).
#[must_use]
pub fn v_of_hemoglobin_over(c_h: f64, range: [f64; 2]) -> f64 {
    let [lo, hi] = range;
    ((c_h.max(lo) / lo).ln() / (hi / lo).ln()).clamp(0.0, 1.0)
}

/// Nodes of the forward table along each axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct TableSize {
    /// Nodes along u (C_m), ≥ 4.
    pub melanin: usize,
    /// Nodes along β_m (evenly over [0, 1]), ≥ 4.
    pub eumelanin: usize,
    /// Nodes along v (C_h), ≥ 4.
    pub hemoglobin: usize,
}

impl Default for TableSize {
    fn default() -> Self {
        Self {
            melanin: 24,
            eumelanin: 11,
            hemoglobin: 16,
        }
    }
}

impl TableSize {
    /// Exact colours the table holds.
    #[must_use]
    pub fn nodes(&self) -> usize {
        self.melanin * self.eumelanin * self.hemoglobin
    }
}

/// The exact model's CIELAB colour at every node, index `(b · n_v + j) · n_u + i`, kept as the
/// bits of each f64 so that the cached file reads back to the same values.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ForwardTable {
    size: TableSize,
    /// The C_h range [C_lo, C_hi] of the v axis.
    hemoglobin_range: [f64; 2],
    lab_bits: Vec<[u64; 3]>,
}

/// The cache key of a table over the C_h range `hemoglobin_range`: everything its nodes depend
/// on, as text with every float's bits.
#[must_use]
pub fn cache_key(size: TableSize, base: &SkinParams, hemoglobin_range: [f64; 2]) -> String {
    let ad = AddingDoublingOptions::default();
    format!(
        "maps-forward-table v2; nodes u{} b{} v{}; knee {:016x}; melanin {:016x}..{:016x}; \
         hemoglobin {:016x}..{:016x}; step {:016x} nm; exact quadrature {} g {:016x}; base {base:?}",
        size.melanin,
        size.eumelanin,
        size.hemoglobin,
        MELANIN_KNEE.to_bits(),
        MELANIN_RANGE[0].to_bits(),
        MELANIN_RANGE[1].to_bits(),
        hemoglobin_range[0].to_bits(),
        hemoglobin_range[1].to_bits(),
        STEP_NM.to_bits(),
        ad.quadrature_points(),
        ad.g().to_bits(),
    )
}

impl ForwardTable {
    /// Build the table over [`HEMOGLOBIN_RANGE`] with the exact model, skins built on `base`.
    pub fn build(size: TableSize, base: SkinParams) -> Result<Self, FitError> {
        Self::build_over(size, base, HEMOGLOBIN_RANGE)
    }

    /// Build the table with its C_h axis over `hemoglobin_range` (0 < C_lo < C_hi ≤ 1) with the
    /// exact model (rayon over nodes), skins built on `base`.
    pub fn build_over(
        size: TableSize,
        base: SkinParams,
        hemoglobin_range: [f64; 2],
    ) -> Result<Self, FitError> {
        // The layer cache reuses each layer's operators across nodes that share it (the dermis
        // depends on C_h only, the epidermis on C_m and β_m only); a cached solve equals an
        // uncached one bit for bit.
        let exact = Forward::Exact(AddingDoublingOptions::default().with_layer_cache(true));
        let model = ColourModel::with_forward(STEP_NM, exact, base)?;
        let n = size.nodes();
        let lab = (0..n)
            .into_par_iter()
            .map(|k| {
                let i = k % size.melanin;
                let j = (k / size.melanin) % size.hemoglobin;
                let b = k / (size.melanin * size.hemoglobin);
                let skin = model.skin(
                    melanin_of_u(i as f64 / (size.melanin - 1) as f64),
                    b as f64 / (size.eumelanin - 1) as f64,
                    hemoglobin_of_v_over(j as f64 / (size.hemoglobin - 1) as f64, hemoglobin_range),
                )?;
                let lab = model.lab(&skin)?;
                Ok([lab.l, lab.a, lab.b].map(f64::to_bits))
            })
            .collect::<Result<Vec<_>, FitError>>()?;
        Ok(Self {
            size,
            hemoglobin_range,
            lab_bits: lab,
        })
    }

    /// The slice at one β_m straight from the exact model (`nu` × `nv` nodes on the table's u, v
    /// axes, skins built on `base`): what [`ForwardTable::slice`] interpolates, without the β_m
    /// axis, for a search over skins that differ in more than C_m, β_m, C_h.
    pub fn exact_slice(
        nu: usize,
        nv: usize,
        base: SkinParams,
        beta: f64,
    ) -> Result<Slice, FitError> {
        let exact = Forward::Exact(AddingDoublingOptions::default().with_layer_cache(true));
        let model = ColourModel::with_forward(STEP_NM, exact, base)?;
        let nodes = (0..nu * nv)
            .into_par_iter()
            .map(|k| {
                let (i, j) = (k % nu, k / nu);
                let skin = model.skin(
                    melanin_of_u(i as f64 / (nu - 1) as f64),
                    beta,
                    hemoglobin_of_v(j as f64 / (nv - 1) as f64),
                )?;
                let lab = model.lab(&skin)?;
                Ok([lab.l, lab.a, lab.b])
            })
            .collect::<Result<Vec<_>, FitError>>()?;
        Ok(Slice::new(nu, nv, &nodes, beta, HEMOGLOBIN_RANGE))
    }

    /// The node counts.
    #[must_use]
    pub fn size(&self) -> TableSize {
        self.size
    }

    /// The C_h range [C_lo, C_hi] of the table's v axis.
    #[must_use]
    pub fn hemoglobin_range(&self) -> [f64; 2] {
        self.hemoglobin_range
    }

    /// Whether a table read back from the cache has the shape its size says.
    #[must_use]
    pub fn is_whole(&self) -> bool {
        let s = self.size;
        let [lo, hi] = self.hemoglobin_range;
        s.melanin >= 4
            && 0.0 < lo
            && lo < hi
            && hi <= 1.0
            && s.eumelanin >= 4
            && s.hemoglobin >= 4
            && self.lab_bits.len() == s.nodes()
            && self
                .lab_bits
                .iter()
                .flatten()
                .all(|v| f64::from_bits(*v).is_finite())
    }

    /// The slice at eumelanin blend `beta` ∈ [0, 1]: cubic Lagrange interpolation along β_m
    /// through the four nearest node planes.
    #[must_use]
    pub fn slice(&self, beta: f64) -> Slice {
        let s = self.size;
        let x = beta.clamp(0.0, 1.0) * (s.eumelanin - 1) as f64;
        let first = (x.floor() as usize).saturating_sub(1).min(s.eumelanin - 4);
        let t = x - first as f64;
        // Lagrange weights on nodes first..first+3 at offset t.
        let w: [f64; 4] = std::array::from_fn(|m| {
            (0..4)
                .filter(|&q| q != m)
                .map(|q| (t - q as f64) / (m as f64 - q as f64))
                .product()
        });
        let plane = s.melanin * s.hemoglobin;
        let nodes: Vec<[f64; 3]> = (0..plane)
            .map(|k| {
                let mut lab = [0.0; 3];
                for (m, wm) in w.iter().enumerate() {
                    let node = self.lab_bits[(first + m) * plane + k];
                    for c in 0..3 {
                        lab[c] += wm * f64::from_bits(node[c]);
                    }
                }
                lab
            })
            .collect();
        Slice::new(s.melanin, s.hemoglobin, &nodes, beta, self.hemoglobin_range)
    }
}

/// A (u, v) slice at one β_m: Catmull–Rom bicubic interpolation ([CR74]) of CIELAB, with one ghost
/// node (linear extrapolation) on every side. Each cell keeps its bicubic as 16 power-basis
/// coefficients (the Catmull–Rom basis matrix applied to its 4 × 4 nodes on both sides), so that
/// a lookup is three short Horner schemes on four-lane (L*, a*, b*, 0) values.
#[derive(Debug, Clone, PartialEq)]
pub struct Slice {
    nu: usize,
    nv: usize,
    /// Per cell (row-major in v), coefficient of tu^k tv^l at `[l * 4 + k]`.
    cells: Vec<[Lanes; 16]>,
    beta: f64,
    hemoglobin_range: [f64; 2],
}

/// L*, a*, b* and a zero: four lanes that vectorise.
type Lanes = [f64; 4];

/// The Catmull–Rom weights w_a(t) = Σ_k `CATMULL_ROM[a][k]` t^k on the nodes a = 0..4 around a
/// cell (nodes 1 and 2 its ends).
const CATMULL_ROM: [[f64; 4]; 4] = [
    [0.0, -0.5, 1.0, -0.5],
    [1.0, 0.0, -2.5, 1.5],
    [0.0, 0.5, 2.0, -1.5],
    [0.0, 0.0, -0.5, 0.5],
];

#[inline(always)]
fn fma4(acc: Lanes, x: Lanes, t: f64) -> Lanes {
    [
        acc[0] * t + x[0],
        acc[1] * t + x[1],
        acc[2] * t + x[2],
        acc[3] * t + x[3],
    ]
}

/// Cell index and offset of unit coordinate `x` on `n` nodes.
#[inline]
fn cell(x: f64, n: usize) -> (usize, f64) {
    let s = x.clamp(0.0, 1.0) * (n - 1) as f64;
    let i = (s as usize).min(n - 2);
    (i, s - i as f64)
}

impl Slice {
    fn new(
        nu: usize,
        nv: usize,
        nodes: &[[f64; 3]],
        beta: f64,
        hemoglobin_range: [f64; 2],
    ) -> Self {
        let (pu, pv) = (nu + 2, nv + 2);
        let mut padded = vec![[0.0; 3]; pu * pv];
        let at = |i: isize, j: isize| -> [f64; 3] {
            // Ghosts: linear extrapolation from the two nearest nodes along each axis.
            let ext = |k: isize, n: usize| -> (usize, usize, f64) {
                if k < 0 {
                    (0, 1, -1.0)
                } else if k >= n as isize {
                    (n - 1, n - 2, -1.0)
                } else {
                    (k as usize, k as usize, 0.0)
                }
            };
            let (i0, i1, fi) = ext(i, nu);
            let (j0, j1, fj) = ext(j, nv);
            let node = |a: usize, b: usize| nodes[b * nu + a];
            std::array::from_fn(|c| {
                let base = node(i0, j0)[c];
                let du = node(i1, j0)[c] - base;
                let dv = node(i0, j1)[c] - base;
                base + fi * du + fj * dv
            })
        };
        for j in 0..pv {
            for i in 0..pu {
                padded[j * pu + i] = at(i as isize - 1, j as isize - 1);
            }
        }
        let cells = (0..(nv - 1) * (nu - 1))
            .map(|c| {
                let (i, j) = (c % (nu - 1), c / (nu - 1));
                let mut coef = [[0.0; 4]; 16];
                for (kl, out) in coef.iter_mut().enumerate() {
                    let (k, l) = (kl % 4, kl / 4);
                    for b in 0..4 {
                        for a in 0..4 {
                            let w = CATMULL_ROM[a][k] * CATMULL_ROM[b][l];
                            if w != 0.0 {
                                let node = padded[(j + b) * pu + i + a];
                                for ch in 0..3 {
                                    out[ch] += w * node[ch];
                                }
                            }
                        }
                    }
                }
                coef
            })
            .collect();
        Self {
            nu,
            nv,
            cells,
            beta,
            hemoglobin_range,
        }
    }

    /// The eumelanin blend β_m of the slice.
    #[must_use]
    pub fn eumelanin(&self) -> f64 {
        self.beta
    }

    /// C_h of the unit coordinate v on the slice's axis.
    #[must_use]
    pub fn hemoglobin_of_v(&self, v: f64) -> f64 {
        hemoglobin_of_v_over(v, self.hemoglobin_range)
    }

    /// The unit coordinate v of C_h on the slice's axis.
    #[must_use]
    pub fn v_of_hemoglobin(&self, c_h: f64) -> f64 {
        v_of_hemoglobin_over(c_h, self.hemoglobin_range)
    }

    #[inline(always)]
    fn locate(&self, u: f64, v: f64) -> (&[Lanes; 16], f64, f64) {
        let (i, tu) = cell(u, self.nu);
        let (j, tv) = cell(v, self.nv);
        (&self.cells[j * (self.nu - 1) + i], tu, tv)
    }

    /// CIELAB at unit coordinates (u, v) ∈ [0, 1]² (clamped).
    #[inline]
    #[must_use]
    pub fn lab(&self, u: f64, v: f64) -> [f64; 3] {
        let (c, tu, tv) = self.locate(u, v);
        let row = |l: usize| {
            let r = fma4(c[l * 4 + 3], c[l * 4 + 2], tu);
            let r = fma4(r, c[l * 4 + 1], tu);
            fma4(r, c[l * 4], tu)
        };
        let f = fma4(fma4(fma4(row(3), row(2), tv), row(1), tv), row(0), tv);
        [f[0], f[1], f[2]]
    }

    /// CIELAB at (u, v) and its derivatives ∂/∂u and ∂/∂v.
    #[inline]
    #[must_use]
    pub fn lab_and_gradient(&self, u: f64, v: f64) -> ([f64; 3], [f64; 3], [f64; 3]) {
        let (c, tu, tv) = self.locate(u, v);
        // Per power of tv: the row polynomial in tu and its tu-derivative.
        let mut r = [[0.0; 4]; 4];
        let mut ru = [[0.0; 4]; 4];
        for l in 0..4 {
            let k = &c[l * 4..l * 4 + 4];
            r[l] = fma4(fma4(fma4(k[3], k[2], tu), k[1], tu), k[0], tu);
            let d3 = k[3].map(|x| 3.0 * x);
            let d2 = k[2].map(|x| 2.0 * x);
            ru[l] = fma4(fma4(d3, d2, tu), k[1], tu);
        }
        let f = fma4(fma4(fma4(r[3], r[2], tv), r[1], tv), r[0], tv);
        let fu = fma4(fma4(fma4(ru[3], ru[2], tv), ru[1], tv), ru[0], tv);
        let d3 = r[3].map(|x| 3.0 * x);
        let d2 = r[2].map(|x| 2.0 * x);
        let fv = fma4(fma4(d3, d2, tv), r[1], tv);
        let su = (self.nu - 1) as f64;
        let sv = (self.nv - 1) as f64;
        (
            [f[0], f[1], f[2]],
            [fu[0] * su, fu[1] * su, fu[2] * su],
            [fv[0] * sv, fv[1] * sv, fv[2] * sv],
        )
    }
}
