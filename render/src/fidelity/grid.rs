//! The profile grid of a skin with chromophore maps (docs/physics.md §19.2): one table per node
//! over the box of parameters its maps use, each built as a scalar skin's table is
//! ([`super::tables::skin_table`], through the disk cache), at a resolution chosen from the
//! interpolation error measured against directly built tables at the cells' centres.

use super::FidelityKnobs;
use super::tables::skin_table;
use crate::bssrdf::grid::{AXIS_KNEES, unwarp, warp};
use crate::bssrdf::{Corners, ProfileGrid, ProfileTable};
use crate::media::SkinMedia;
use multipole::{Method, MultipoleError};
use rayon::prelude::*;
use skin_optics::SkinParams;
use std::collections::HashMap;
use std::sync::{Arc, Mutex};

/// Default target of the grid's interpolation error: the relative L1 error of the radial energy
/// 2πr R(r) at the worst wavelength (every 20 nm), measured at the cells' centres.
pub const DEFAULT_GRID_ERROR: f32 = 0.02;

/// Most nodes per axis (2⁵ + 1): the refinement stops there whatever the error.
pub const MAX_NODES_PER_AXIS: usize = 33;

/// Most tables in a grid (33², the finest grid over two parameters; a table is about 40 KiB): the
/// refinement stops before a grid would hold more, whatever the error (`explain` shows it).
pub const MAX_GRID_TABLES: usize = 33 * 33;

/// Most cell centres the error is measured at per refinement step (spread over the cells).
const MAX_PROBED_CELLS: usize = 24;

/// Wavelengths of the error measure, nm.
const ERROR_NM: [f32; 21] = [
    380.0, 400.0, 420.0, 440.0, 460.0, 480.0, 500.0, 520.0, 540.0, 560.0, 580.0, 600.0, 620.0,
    640.0, 660.0, 680.0, 700.0, 720.0, 740.0, 760.0, 780.0,
];

/// What a node's table is built from besides its parameters.
#[derive(Debug, Clone, Copy)]
pub struct GridSettings<'a> {
    /// The material's other parameters (oxygenation, thickness, η, extensions).
    pub params: &'a SkinParams,
    /// Henyey–Greenstein g of both layers.
    pub phase_g: f64,
    /// The skin's surface, the boundary of the totals (`media::SkinMedia::surface`).
    pub surface: multipole::Surface,
    /// The profile method.
    pub method: Method,
    /// Monte Carlo shape escapes (`SkinKnobs::shape_escapes`).
    pub shape_escapes: Option<u64>,
    /// The fidelity knobs of the material's tables.
    pub fidelity: &'a FidelityKnobs,
    /// Target of the interpolation error ([`DEFAULT_GRID_ERROR`]).
    pub target: f32,
}

/// Tables built so far, keyed by their parameters' bits.
type Memo = Mutex<HashMap<[u32; 3], Arc<ProfileTable>>>;

impl GridSettings<'_> {
    /// The table at parameters `p` = (C_m, β_m, C_h), built once.
    fn table(&self, memo: &Memo, p: [f32; 3]) -> Result<Arc<ProfileTable>, MultipoleError> {
        let key = p.map(f32::to_bits);
        if let Some(t) = memo.lock().expect("no panics while held").get(&key) {
            return Ok(t.clone());
        }
        let params = self
            .params
            .with_melanin(f64::from(p[0]))?
            .with_eumelanin_blend(f64::from(p[1]))?
            .with_hemoglobin(f64::from(p[2]))?;
        let media = SkinMedia::new(&params, self.phase_g)
            .map_err(|e| e.source)?
            .with_surface(self.surface);
        let (table, _) = skin_table(
            &params,
            &media,
            self.method,
            self.shape_escapes,
            self.fidelity,
        )?;
        let table = Arc::new(table);
        memo.lock()
            .expect("no panics while held")
            .insert(key, table.clone());
        Ok(table)
    }
}

/// The relative L1 error of `grid`'s interpolated 2πr R(r) against `direct`'s, on `direct`'s
/// radii, at the worst of [`ERROR_NM`] (wavelengths without reflectance left out).
#[must_use]
pub fn interpolation_error(grid: &Corners<'_>, direct: &ProfileTable) -> f32 {
    let radii = direct.radii_mm();
    ERROR_NM
        .iter()
        .map(|&nm| {
            let (mut diff, mut norm) = (0.0f64, 0.0f64);
            for w in radii.windows(2) {
                let (r, dr) = (w[0], w[1] - w[0]);
                let d = f64::from(direct.eval(nm, r));
                let g = f64::from(grid.eval_nm(nm, r));
                diff += (g - d).abs() * f64::from(r * dr);
                norm += d * f64::from(r * dr);
            }
            if norm > 0.0 {
                (diff / norm) as f32
            } else {
                0.0
            }
        })
        .fold(0.0, f32::max)
}

/// The grid over `range` (per axis [lo, hi]; lo = hi gives one node): 2 nodes per varying axis,
/// doubled in resolution until the error at the cells' centres is at most `settings.target`, an
/// axis has [`MAX_NODES_PER_AXIS`] nodes or the next grid would hold more than
/// [`MAX_GRID_TABLES`] tables.
pub fn profile_grid(
    settings: &GridSettings<'_>,
    range: [[f32; 2]; 3],
) -> Result<ProfileGrid, MultipoleError> {
    let memo: Memo = Mutex::new(HashMap::new());
    let mut nodes = range.map(|[lo, hi]| if hi > lo { 2 } else { 1 });
    loop {
        let axes: [Vec<f32>; 3] = std::array::from_fn(|k| {
            let [lo, hi] = range[k];
            let n = nodes[k];
            if n == 1 {
                return vec![lo];
            }
            let (wl, wh) = (warp(AXIS_KNEES[k], lo), warp(AXIS_KNEES[k], hi));
            (0..n)
                .map(|i| match i {
                    0 => lo,
                    _ if i == n - 1 => hi,
                    _ => unwarp(AXIS_KNEES[k], wl + (wh - wl) * i as f32 / (n - 1) as f32)
                        .clamp(lo, hi),
                })
                .collect()
        });
        let points: Vec<[f32; 3]> = (0..nodes[2])
            .flat_map(|c| (0..nodes[1]).flat_map(move |b| (0..nodes[0]).map(move |a| [a, b, c])))
            .map(|[a, b, c]| [axes[0][a], axes[1][b], axes[2][c]])
            .collect();
        let tables = points
            .par_iter()
            .map(|&p| settings.table(&memo, p))
            .collect::<Result<Vec<_>, _>>()?;
        let mut grid = ProfileGrid::new(axes.clone(), tables, 0.0);
        let centres = cell_centres(&axes);
        let step = centres.len().div_ceil(MAX_PROBED_CELLS).max(1);
        let probed: Vec<[f32; 3]> = centres.into_iter().step_by(step).collect();
        let errors = probed
            .par_iter()
            .map(|&p| {
                let direct = settings.table(&memo, p)?;
                Ok(interpolation_error(&grid.corners(p), &direct))
            })
            .collect::<Result<Vec<f32>, MultipoleError>>()?;
        grid.max_error = errors.into_iter().fold(0.0, f32::max);
        let next = nodes.map(|n| if n > 1 { 2 * n - 1 } else { 1 });
        let full = nodes.iter().any(|&n| n >= MAX_NODES_PER_AXIS)
            || next.iter().product::<usize>() > MAX_GRID_TABLES;
        if grid.max_error <= settings.target || full || nodes == [1, 1, 1] {
            return Ok(grid);
        }
        nodes = next;
    }
}

/// The centre of every cell of the grid with node values `axes`, midway in each axis's warped
/// coordinate (a one-node axis keeps its node).
fn cell_centres(axes: &[Vec<f32>; 3]) -> Vec<[f32; 3]> {
    let mids = |k: usize| -> Vec<f32> {
        let a = &axes[k];
        if a.len() == 1 {
            a.clone()
        } else {
            let w = |v: f32| warp(AXIS_KNEES[k], v);
            a.windows(2)
                .map(|p| unwarp(AXIS_KNEES[k], 0.5 * (w(p[0]) + w(p[1]))))
                .collect()
        }
    };
    let [m0, m1, m2] = [mids(0), mids(1), mids(2)];
    let mut out = Vec::with_capacity(m0.len() * m1.len() * m2.len());
    for &c in &m2 {
        for &b in &m1 {
            for &a in &m0 {
                out.push([a, b, c]);
            }
        }
    }
    out
}
