//! Radial profiles over a box of skin parameters: one [`ProfileTable`] per node of a grid over
//! (C_m, β_m, C_h) (an axis whose range is one value has one node), interpolated multilinearly
//! in ln R(r) at a hit's parameters (docs/physics.md §19.2). The grid is built by
//! `crate::fidelity::grid`, which chooses its resolution from the interpolation error it measures.

use super::ProfileTable;
use super::table::RowPlace;
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
    /// Every node's R_tot at each of its tabulation rows, node after node, `rows` per node, when
    /// all nodes share their rows (§19.2; else empty): the totals at a hit read them without
    /// resolving each table's rows.
    totals: Vec<f32>,
    /// Rows per node in `totals` (0 when the nodes' rows differ).
    rows: usize,
}

/// Up to eight nodes of a grid and their multilinear weights (those of weight 0 left out).
#[derive(Debug, Clone, Copy)]
pub struct Corners<'a> {
    grid: &'a ProfileGrid,
    /// Node index and weight of each corner, the first `n` used.
    nodes: [(u32, f32); 8],
    n: usize,
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
        let warped = warped_axes(&axes);
        let shared = tables.iter().all(|t| t.same_rows(&tables[0]));
        let (totals, rows) = if shared {
            let totals = tables.iter().flat_map(|t| t.row_totals()).collect();
            (totals, tables[0].wavelengths())
        } else {
            (Vec::new(), 0)
        };
        Self {
            axes,
            warped,
            tables,
            max_error,
            totals,
            rows,
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

    /// The index of the node at the low end of the cell holding `p` = (C_m, β_m, C_h) in C_m and
    /// C_h (each clamped to its axis): the least absorbing of the cell's corners, whose profile
    /// rows end within a few percent of theirs (where under 0.1% of a row's energy is left).
    /// `None` when β_m has more than one node (β_m moves absorption between wavelengths).
    #[must_use]
    pub fn low_corner(&self, p: [f32; 3]) -> Option<usize> {
        if self.axes[1].len() > 1 {
            return None;
        }
        let low = |k: usize| {
            let axis = &self.axes[k];
            axis.partition_point(|&a| a <= p[k])
                .clamp(1, axis.len().max(1))
                .saturating_sub(1)
                .min(axis.len() - 1)
        };
        Some(low(0) + self.axes[0].len() * self.axes[1].len() * low(2))
    }

    /// The tables around parameters `p` = (C_m, β_m, C_h) and their multilinear weights (each
    /// coordinate clamped to its axis).
    #[must_use]
    pub fn corners(&self, p: [f32; 3]) -> Corners<'_> {
        let (nodes, n) = node_weights(&self.axes, &self.warped, p);
        Corners {
            grid: self,
            nodes,
            n,
        }
    }
}

/// The warped node values ([`warp`]) of each axis of `axes` (C_m, β_m, C_h).
#[must_use]
pub fn warped_axes(axes: &[Vec<f32>; 3]) -> [Vec<f32>; 3] {
    std::array::from_fn(|k| axes[k].iter().map(|&v| warp(AXIS_KNEES[k], v)).collect())
}

/// The nodes around parameters `p` = (C_m, β_m, C_h) of a grid with node values `axes` (warped:
/// `warped`), C_m fastest, and their multilinear weights, linear in each axis's warped coordinate
/// (each coordinate clamped to its axis); those of weight 0 left out, the first `n` used.
#[must_use]
pub fn node_weights(
    axes: &[Vec<f32>; 3],
    warped: &[Vec<f32>; 3],
    p: [f32; 3],
) -> ([(u32, f32); 8], usize) {
    let locate = |k: usize, x: f32| -> (usize, f32) {
        let axis = &axes[k];
        if axis.len() == 1 {
            return (0, 0.0);
        }
        let last = axis.len() - 1;
        let i = axis.partition_point(|&a| a <= x).clamp(1, last) - 1;
        let w = &warped[k];
        let t = ((warp(AXIS_KNEES[k], x) - w[i]) / (w[i + 1] - w[i])).clamp(0.0, 1.0);
        (i, t)
    };
    let at = [0, 1, 2].map(|k| locate(k, p[k]));
    let (n0, n1) = (axes[0].len(), axes[1].len());
    let mut nodes = [(0u32, 0.0f32); 8];
    let mut n = 0;
    for c in 0..8 {
        let bits = [c & 1, (c >> 1) & 1, (c >> 2) & 1];
        let mut w = 1.0;
        let mut index = [0usize; 3];
        for k in 0..3 {
            let (i, t) = at[k];
            w *= if bits[k] == 1 { t } else { 1.0 - t };
            index[k] = i + bits[k];
        }
        if w > 0.0 {
            nodes[n] = ((index[0] + n0 * (index[1] + n1 * index[2])) as u32, w);
            n += 1;
        }
    }
    (nodes, n)
}

impl<'a> Corners<'a> {
    /// The corners' tables and weights.
    fn tables(&self) -> impl Iterator<Item = (&'a ProfileTable, f32)> + Clone + '_ {
        let tables = &self.grid.tables;
        self.nodes[..self.n]
            .iter()
            .map(move |&(i, w)| (&*tables[i as usize], w))
    }

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

    /// Where each active lane of `wl` falls on the first corner's rows, for every corner when
    /// the grid's nodes share their rows (`None` for terminated lanes, and for every lane when
    /// the rows differ: each table then places it on its own).
    fn places(&self, wl: &SampledWavelengths) -> [Option<RowPlace>; N_WAVELENGTHS] {
        let first = &self.grid.tables[self.nodes[0].0 as usize];
        std::array::from_fn(|k| {
            (self.grid.rows > 0 && wl.pdf()[k] > 0.0).then(|| first.place_lane(wl, k))
        })
    }

    /// R(r) at `r_mm` for each active lane of `wl` (0 for terminated lanes), mm⁻².
    #[must_use]
    pub fn eval(&self, wl: &SampledWavelengths, r_mm: f32) -> SampledSpectrum {
        let [at] = Self::eval_sets([self], wl, r_mm);
        at
    }

    /// [`Self::eval`] of `self` and `other` at the same radius and wavelengths: on one grid, a
    /// node the two share (neighbouring points mostly lie in one cell) is read once.
    #[must_use]
    pub fn eval_pair(
        &self,
        other: &Self,
        wl: &SampledWavelengths,
        r_mm: f32,
    ) -> [SampledSpectrum; 2] {
        if std::ptr::eq(self.grid, other.grid) {
            Self::eval_sets([self, other], wl, r_mm)
        } else {
            [self.eval(wl, r_mm), other.eval(wl, r_mm)]
        }
    }

    /// [`Self::eval`] of each of `sets` (corners of one grid), each distinct node's table
    /// evaluated once and the logarithm of each of its values taken once.
    fn eval_sets<const S: usize>(
        sets: [&Self; S],
        wl: &SampledWavelengths,
        r_mm: f32,
    ) -> [SampledSpectrum; S] {
        let grid = sets[0].grid;
        let places = sets[0].places(wl);
        // The distinct nodes, and where each set's corners are among them.
        let mut nodes = [0u32; 16];
        let mut m = 0;
        let mut slots = [[0usize; 8]; S];
        for (set, slot) in sets.iter().zip(&mut slots) {
            for (c, &(node, _)) in set.nodes[..set.n].iter().enumerate() {
                slot[c] = match nodes[..m].iter().position(|&x| x == node) {
                    Some(j) => j,
                    None => {
                        nodes[m] = node;
                        m += 1;
                        m - 1
                    }
                };
            }
        }
        // Each node's R and ln R per lane (ln only of positive values: the blend is linear
        // wherever a corner's value is 0).
        let mut at = [[(0.0f32, 0.0f32); 16]; N_WAVELENGTHS];
        let radius = super::TableRadius::new(r_mm);
        for (u, &node) in nodes[..m].iter().enumerate() {
            let table = &grid.tables[node as usize];
            let lanes: [_; N_WAVELENGTHS] = std::array::from_fn(|k| match places[k] {
                Some(place) => Some(table.at_place(place)),
                None => (grid.rows == 0 && wl.pdf()[k] > 0.0).then(|| table.at_lane(wl, k)),
            });
            let r = table.eval_each_at(&lanes, radius);
            for k in 0..N_WAVELENGTHS {
                at[k][u] = (r[k], if r[k] > 0.0 { r[k].ln() } else { 0.0 });
            }
        }
        std::array::from_fn(|s| {
            let (set, slot) = (sets[s], &slots[s]);
            SampledSpectrum(std::array::from_fn(|k| {
                let values = set.nodes[..set.n]
                    .iter()
                    .zip(slot)
                    .map(|(&(_, w), &u)| (at[k][u], w));
                // As `Self::blend`, with the logarithms taken above.
                if values.clone().all(|((v, _), _)| v > 0.0) {
                    values.map(|((_, ln_v), w)| w * ln_v).sum::<f32>().exp()
                } else {
                    values.map(|((v, _), w)| w * v).sum()
                }
            }))
        })
    }

    /// R(r) at one wavelength `nm`, mm⁻².
    #[must_use]
    pub fn eval_nm(&self, nm: f32, r_mm: f32) -> f32 {
        Self::blend(self.tables().map(|(t, w)| (t.eval(nm, r_mm), w)))
    }

    /// The total diffuse reflectance R_tot at `nm`, interpolated alike.
    #[must_use]
    pub fn total(&self, nm: f32) -> f32 {
        Self::blend(self.tables().map(|(t, w)| (t.total(nm), w)))
    }

    /// [`Self::total`] at the path's wavelength `k`, through each table's rows.
    #[must_use]
    pub fn total_lane(&self, wl: &SampledWavelengths, k: usize) -> f32 {
        Self::blend(self.tables().map(|(t, w)| (t.at_lane(wl, k).total(), w)))
    }

    /// [`Self::total_lane`] at every lane of `wl` (terminated ones too), each wavelength placed
    /// once for all corners and the totals read from the grid's own array of them.
    #[must_use]
    pub fn totals(&self, wl: &SampledWavelengths) -> SampledSpectrum {
        let rows = self.grid.rows;
        if rows == 0 {
            return SampledSpectrum(std::array::from_fn(|k| self.total_lane(wl, k)));
        }
        let first = &self.grid.tables[self.nodes[0].0 as usize];
        let totals = &self.grid.totals;
        SampledSpectrum(std::array::from_fn(|k| {
            let (lower, upper, t) = first.place_lane(wl, k).rows(rows);
            let mut at = [(0.0f32, 0.0f32); 8];
            for (slot, &(node, w)) in at.iter_mut().zip(&self.nodes[..self.n]) {
                let base = node as usize * rows;
                // As `ProfileTable::at_lane(..).total()`: the rows' totals mixed in this order.
                *slot = (
                    (1.0 - t) * totals[base + lower] + t * totals[base + upper],
                    w,
                );
            }
            Self::blend(at[..self.n].iter().copied())
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::super::TableOptions;
    use super::*;
    use multipole::Method;
    use rand::{Rng, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;
    use rayon::prelude::*;
    use skin_optics::{Preset, SkinParams};

    /// Two nodes per axis: C_m, β_m, C_h.
    const BOX: [[f32; 2]; 3] = [[0.02, 0.3], [0.3, 0.8], [0.005, 0.1]];

    /// The diffusion tables at the box's corners (C_m fastest), on 10-nm rows, or on 20-nm rows
    /// at the lowest node when `mixed_rows`.
    fn corner_tables(mixed_rows: bool) -> Vec<Arc<ProfileTable>> {
        let base = SkinParams::preset(Preset::Light);
        (0..8)
            .into_par_iter()
            .map(|c| {
                let v = |k: usize| f64::from(BOX[k][(c >> k) & 1]);
                let params = base
                    .with_melanin(v(0))
                    .and_then(|p| p.with_eumelanin_blend(v(1)))
                    .and_then(|p| p.with_hemoglobin(v(2)))
                    .unwrap();
                let opts = TableOptions {
                    step_nm: if mixed_rows && c == 0 { 20.0 } else { 10.0 },
                    radii: 64,
                    ..TableOptions::default()
                };
                Arc::new(ProfileTable::build(&params, Method::Multipole, &opts).unwrap())
            })
            .collect()
    }

    /// The low corner of a point's cell is its least absorbing node, and its profile's rows end
    /// within 10% of every corner's (measured at most 5.1% short, at 400–440 nm, where each row
    /// keeps under 0.1% of its energy beyond its end):
    /// on a 3 × 1 × 2 grid over C_m 0.02–0.3 and C_h 0.005–0.1 (β_m 0.3), points between the
    /// first two C_m nodes take node 0, between the last two node 1 (and past the top node the
    /// top node); a grid with two β_m nodes has none.
    #[test]
    fn the_low_corner_reaches_as_far_as_its_cells_corners() {
        let base = SkinParams::preset(Preset::Light);
        let axes = [vec![0.02f32, 0.08, 0.3], vec![0.3f32], vec![0.005f32, 0.1]];
        let tables: Vec<Arc<ProfileTable>> = (0..6)
            .into_par_iter()
            .map(|i| {
                let params = base
                    .with_melanin(f64::from(axes[0][i % 3]))
                    .and_then(|p| p.with_eumelanin_blend(0.3))
                    .and_then(|p| p.with_hemoglobin(f64::from(axes[2][i / 3])))
                    .unwrap();
                let opts = TableOptions {
                    step_nm: 20.0,
                    radii: 64,
                    ..TableOptions::default()
                };
                Arc::new(ProfileTable::build(&params, Method::Multipole, &opts).unwrap())
            })
            .collect();
        let grid = ProfileGrid::new(axes.clone(), tables, 0.0);
        for (p, want) in [
            ([0.05f32, 0.3, 0.05], 0),
            ([0.2, 0.3, 0.05], 1),
            ([0.4, 0.3, 0.2], 5),
        ] {
            let low = grid.low_corner(p).unwrap();
            assert_eq!(low, want, "{p:?}");
            let corners = grid.corners(p);
            for nm in (400..=700).step_by(20).map(|nm| nm as f32) {
                let reach = grid.tables()[low].r_max_mm(nm);
                for (table, _) in corners.tables() {
                    assert!(reach >= 0.9 * table.r_max_mm(nm), "{p:?} {nm}: {reach}");
                }
            }
        }
        let two_betas = ProfileGrid::new(
            [vec![0.02], vec![0.3, 0.8], vec![0.005]],
            corner_tables(false)[..2].to_vec(),
            0.0,
        );
        assert_eq!(two_betas.low_corner([0.02, 0.5, 0.005]), None);
    }

    /// The corners' blend against each table evaluated on its own: at random parameters in the
    /// box, random path wavelengths (some with the secondary lanes terminated) and random radii,
    /// R(r) and R_tot per lane are ∏ v_c^{w_c} of the tables' own values (linear Σ w_c v_c where
    /// a corner's profile has ended), with the weights computed here in f64, linear in the warped
    /// coordinates, within 2·10⁻⁵ relative (the f32 sum of up to eight logarithms, |ln v| ≤ 30,
    /// each weight within a few ulp of 1: 3·10⁻⁷ × 30 ≈ 10⁻⁵), plus 4·10⁻⁷ Σ v_c where the blend
    /// is linear (a weight near 0 is known to a few ulp of 1, not of itself). Both the grid whose nodes share their
    /// rows (totals read from the grid's array) and one whose nodes do not (each table places the
    /// wavelength itself) are checked; where the rows are shared, the totals of every lane at
    /// once equal the per-lane, per-table path bit for bit, and two points' profiles evaluated
    /// together equal each evaluated alone.
    #[test]
    fn corner_blend_is_the_product_of_each_tables_values() {
        let axes = BOX.map(|a| a.to_vec());
        for mixed in [false, true] {
            let grid = ProfileGrid::new(axes.clone(), corner_tables(mixed), 0.0);
            assert_eq!(grid.rows == 0, mixed);
            let r_max = grid
                .tables()
                .iter()
                .map(|t| *t.radii_mm().last().unwrap())
                .fold(0.0f32, f32::max);
            let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
            let (mut linear, mut geometric) = (0, 0);
            for trial in 0..400 {
                let p: [f32; 3] = std::array::from_fn(|k| rng.random_range(BOX[k][0]..BOX[k][1]));
                let mut wl = SampledWavelengths::sample_visible(rng.random());
                if trial % 4 == 0 {
                    wl.terminate_secondary();
                }
                let r_mm = (rng.random_range((1e-3f32).ln()..r_max.ln())).exp();
                let t: [f64; 3] = std::array::from_fn(|k| {
                    let w = |v: f32| f64::from(warp(AXIS_KNEES[k], v));
                    (w(p[k]) - w(BOX[k][0])) / (w(BOX[k][1]) - w(BOX[k][0]))
                });
                let corners: Vec<(&ProfileTable, f64)> = (0..8)
                    .map(|c| {
                        let w = (0..3)
                            .map(|k| if (c >> k) & 1 == 1 { t[k] } else { 1.0 - t[k] })
                            .product::<f64>();
                        (&*grid.tables()[c], w)
                    })
                    .collect();
                let blend = |v: &dyn Fn(&ProfileTable) -> f32| -> (f64, bool) {
                    let vals: Vec<(f64, f64)> = corners
                        .iter()
                        .map(|&(table, w)| (f64::from(v(table)), w))
                        .collect();
                    if vals.iter().all(|&(v, _)| v > 0.0) {
                        (
                            vals.iter().map(|(v, w)| w * v.ln()).sum::<f64>().exp(),
                            true,
                        )
                    } else {
                        (vals.iter().map(|(v, w)| w * v).sum(), false)
                    }
                };
                let at = grid.corners(p);
                let (totals, profile) = (at.totals(&wl), at.eval(&wl, r_mm));
                // A second point (on this two-node grid, in the same cell: every node shared).
                let q: [f32; 3] = std::array::from_fn(|k| rng.random_range(BOX[k][0]..BOX[k][1]));
                let other = grid.corners(q);
                let pair = at.eval_pair(&other, &wl, r_mm);
                for (a, b) in [(pair[0], profile), (pair[1], other.eval(&wl, r_mm))] {
                    assert_eq!(a.0.map(f32::to_bits), b.0.map(f32::to_bits));
                }
                for k in 0..N_WAVELENGTHS {
                    let nm = wl.nm(k);
                    let (want, _) = blend(&|table| table.total(nm));
                    let got = f64::from(totals.0[k]);
                    assert!(
                        (got / want - 1.0).abs() < 2e-5,
                        "{p:?} {nm} nm: R_tot {got} against {want}"
                    );
                    if !mixed {
                        assert_eq!(totals.0[k].to_bits(), at.total_lane(&wl, k).to_bits());
                    }
                    let got = f64::from(profile.0[k]);
                    if wl.pdf()[k] == 0.0 {
                        assert_eq!(got, 0.0);
                        continue;
                    }
                    let (want, positive) = blend(&|table| table.eval(nm, r_mm));
                    // Where the blend is linear, a weight near 0 is known to a few ulp of 1 only.
                    let sum: f64 = corners
                        .iter()
                        .map(|&(table, _)| f64::from(table.eval(nm, r_mm)))
                        .sum();
                    if positive {
                        geometric += 1;
                    } else {
                        linear += 1;
                    }
                    assert!(
                        (got - want).abs() <= 2e-5 * want + 4e-7 * sum,
                        "{p:?} {nm} nm {r_mm} mm: R {got} against {want}"
                    );
                }
            }
            // Both branches of the blend were exercised.
            assert!(linear > 20 && geometric > 200, "{linear} {geometric}");
        }
    }
}
