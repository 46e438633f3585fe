//! Radial profiles over a box of skin parameters: one [`ProfileTable`] per node of a grid over
//! (C_m, β_m, C_h) (an axis whose range is one value has one node), interpolated multilinearly
//! in ln R(r) at a hit's parameters (docs/physics.md §19.2). The grid is built by
//! `crate::fidelity::grid`, which chooses its resolution from the interpolation error it measures.

use super::ProfileTable;
use crate::spectrum::{N_WAVELENGTHS, SampledSpectrum, SampledWavelengths};
use std::sync::Arc;

/// The knee c₀ of each axis's warp w(v) = ln(v + c₀) (C_m, C_h; as the forward table of §18 spaces
/// them: even in the logarithm above the knee, nearly linear below), `None` for a linear axis (β_m).
/// Nodes are even in w and the interpolation weights are linear in w.
pub const AXIS_KNEES: [Option<f32>; 3] = [Some(0.005), None, Some(0.001)];

/// The warped coordinate of `v` on an axis of knee `knee`.
#[must_use]
#[inline]
pub fn warp(knee: Option<f32>, v: f32) -> f32 {
    knee.map_or(v, |c| (v + c).ln())
}

/// The value at warped coordinate `w` on an axis of knee `knee` (the inverse of [`warp`]).
#[must_use]
pub fn unwarp(knee: Option<f32>, w: f32) -> f32 {
    knee.map_or(w, |c| w.exp() - c)
}

/// Profile tables at the nodes of a grid over (C_m, β_m, C_h).
#[derive(Debug, Clone)]
pub struct ProfileGrid {
    /// Node values of each axis (C_m, β_m, C_h), increasing.
    axes: [Vec<f32>; 3],
    /// The same nodes warped ([`warp`]), where the interpolation weights are linear.
    warped: [Vec<f32>; 3],
    /// The tables, C_m fastest, then β_m, then C_h.
    tables: Vec<Arc<ProfileTable>>,
    /// The largest relative L1 error of the interpolated radial energy 2πr R(r) against directly
    /// built profiles, measured at the cells' centres when the grid was built.
    pub max_error: f32,
}

/// Up to eight tables and their multilinear weights (those of weight 0 left out).
#[derive(Debug, Clone, Copy)]
pub struct Corners<'a> {
    tables: [Option<(&'a ProfileTable, f32)>; 8],
}

impl ProfileGrid {
    /// A grid of `tables` (C_m fastest) over node values `axes`; `max_error` as measured.
    ///
    /// # Panics
    /// If the table count is not the product of the axes' lengths or an axis is empty.
    #[must_use]
    pub fn new(axes: [Vec<f32>; 3], tables: Vec<Arc<ProfileTable>>, max_error: f32) -> Self {
        assert!(axes.iter().all(|a| !a.is_empty()), "every axis has a node");
        assert_eq!(
            tables.len(),
            axes.iter().map(Vec::len).product::<usize>(),
            "one table per node"
        );
        let warped =
            std::array::from_fn(|k| axes[k].iter().map(|&v| warp(AXIS_KNEES[k], v)).collect());
        Self {
            axes,
            warped,
            tables,
            max_error,
        }
    }

    /// The node values of each axis (C_m, β_m, C_h).
    #[must_use]
    pub fn axes(&self) -> &[Vec<f32>; 3] {
        &self.axes
    }

    /// Every node's table, C_m fastest.
    #[must_use]
    pub fn tables(&self) -> &[Arc<ProfileTable>] {
        &self.tables
    }

    /// The table at the lowest node of every axis (least melanin and blood: the widest profile).
    #[must_use]
    pub fn lowest(&self) -> &Arc<ProfileTable> {
        &self.tables[0]
    }

    /// The tables around parameters `p` = (C_m, β_m, C_h) and their multilinear weights (each
    /// coordinate clamped to its axis).
    #[must_use]
    pub fn corners(&self, p: [f32; 3]) -> Corners<'_> {
        let locate = |k: usize, x: f32| -> (usize, f32) {
            let axis = &self.axes[k];
            if axis.len() == 1 {
                return (0, 0.0);
            }
            let last = axis.len() - 1;
            let i = axis.partition_point(|&a| a <= x).clamp(1, last) - 1;
            let w = &self.warped[k];
            let t = ((warp(AXIS_KNEES[k], x) - w[i]) / (w[i + 1] - w[i])).clamp(0.0, 1.0);
            (i, t)
        };
        let at = [0, 1, 2].map(|k| locate(k, p[k]));
        let (n0, n1) = (self.axes[0].len(), self.axes[1].len());
        let mut tables = [None; 8];
        for (c, slot) in tables.iter_mut().enumerate() {
            let bits = [c & 1, (c >> 1) & 1, (c >> 2) & 1];
            let mut w = 1.0;
            let mut index = [0usize; 3];
            for k in 0..3 {
                let (i, t) = at[k];
                w *= if bits[k] == 1 { t } else { 1.0 - t };
                index[k] = i + bits[k];
            }
            if w > 0.0 {
                *slot = Some((&*self.tables[index[0] + n0 * (index[1] + n1 * index[2])], w));
            }
        }
        Corners { tables }
    }
}

impl Corners<'_> {
    /// The multilinear interpolation of ln v over the corners' values `v` (weights `w`):
    /// ∏ v_c^{w_c}, exact where v is exponential in the parameters (an absorbing layer's
    /// filter, §19.2); linear where a corner's value is 0 (beyond its profile's end).
    #[inline]
    fn blend(values: impl Iterator<Item = (f32, f32)> + Clone) -> f32 {
        if values.clone().all(|(v, _)| v > 0.0) {
            values.map(|(v, w)| w * v.ln()).sum::<f32>().exp()
        } else {
            values.map(|(v, w)| w * v).sum()
        }
    }

    /// R(r) at `r_mm` for each active lane of `wl` (0 for terminated lanes), mm⁻².
    #[must_use]
    pub fn eval(&self, wl: &SampledWavelengths, r_mm: f32) -> SampledSpectrum {
        let mut at = [[(0.0f32, 0.0f32); 8]; N_WAVELENGTHS];
        let mut n = 0;
        for (table, w) in self.tables.iter().flatten() {
            let lanes: [_; N_WAVELENGTHS] =
                std::array::from_fn(|k| (wl.pdf()[k] > 0.0).then(|| table.at_lane(wl, k)));
            let r = table.eval_each(&lanes, r_mm);
            for k in 0..N_WAVELENGTHS {
                at[k][n] = (r[k], *w);
            }
            n += 1;
        }
        SampledSpectrum(std::array::from_fn(|k| {
            Self::blend(at[k][..n].iter().copied())
        }))
    }

    /// R(r) at one wavelength `nm`, mm⁻².
    #[must_use]
    pub fn eval_nm(&self, nm: f32, r_mm: f32) -> f32 {
        Self::blend(
            self.tables
                .iter()
                .flatten()
                .map(|(t, w)| (t.eval(nm, r_mm), *w)),
        )
    }

    /// The total diffuse reflectance R_tot at `nm`, interpolated alike.
    #[must_use]
    pub fn total(&self, nm: f32) -> f32 {
        Self::blend(self.tables.iter().flatten().map(|(t, w)| (t.total(nm), *w)))
    }

    /// [`Self::total`] at the path's wavelength `k`.
    #[must_use]
    pub fn total_lane(&self, wl: &SampledWavelengths, k: usize) -> f32 {
        Self::blend(
            self.tables
                .iter()
                .flatten()
                .map(|(t, w)| (t.at_lane(wl, k).total(), *w)),
        )
    }
}
