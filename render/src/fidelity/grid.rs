//! The profile grid of a skin with chromophore maps (docs/physics.md §19.2): one table per node
//! over the box of parameters its maps use, each built as a scalar skin's table is
//! ([`super::tables::skin_table`], through the disk cache), at a resolution chosen from the
//! interpolation error measured against directly built tables at the cells' centres.
//!
//! The choice is kept in the disk cache too, as a small record (the node counts and the measured
//! error) under a key of everything it depends on ([`super::key::grid_key`]): a load that finds
//! the record reads only the chosen grid's tables, not the coarser grids' and the cells' centres'
//! of the refinement. A record that is missing, not trusted or out of range is replaced by a new
//! refinement's.

use super::FidelityKnobs;
use super::PhotonPolicy;
use super::key::grid_key;
use super::tables::{Shapes, first_table_key, in_cache_folder, may_choose, node_table};
use crate::bssrdf::grid::{AXIS_KNEES, unwarp, warp};
use crate::bssrdf::{Corners, ProfileGrid, ProfileTable};
use crate::media::SkinMedia;
use multipole::{Method, MultipoleError};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use skin_io::cache::{self, CacheOutcome};
use skin_optics::SkinParams;
use std::collections::HashMap;
use std::path::Path;
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
pub(super) const MAX_PROBED_CELLS: usize = 24;

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

/// Tables built so far and their shapes, keyed by their parameters' bits.
type Memo = Mutex<HashMap<[u32; 3], (Arc<ProfileTable>, Shapes)>>;

impl GridSettings<'_> {
    /// The skin at parameters `p` = (C_m, β_m, C_h) and its layers.
    fn node(&self, p: [f32; 3]) -> Result<(SkinParams, SkinMedia), MultipoleError> {
        let params = self
            .params
            .with_melanin(f64::from(p[0]))?
            .with_eumelanin_blend(f64::from(p[1]))?
            .with_hemoglobin(f64::from(p[2]))?;
        let media = SkinMedia::new(&params, self.phase_g)
            .map_err(|e| e.source)?
            .with_surface(self.surface);
        Ok((params, media))
    }

    /// The table at parameters `p` = (C_m, β_m, C_h), built once; with the shapes `known`
    /// from a record, without reading the table a footprint's photon choice is made from.
    fn table(
        &self,
        memo: &Memo,
        p: [f32; 3],
        known: Option<Shapes>,
    ) -> Result<Arc<ProfileTable>, MultipoleError> {
        let key = p.map(f32::to_bits);
        if let Some((t, _)) = memo.lock().expect("no panics while held").get(&key) {
            return Ok(t.clone());
        }
        let (params, media) = self.node(p)?;
        let (table, shapes) = node_table(
            &params,
            &media,
            self.method,
            self.shape_escapes,
            self.fidelity,
            known,
        )?;
        let table = Arc::new(table);
        memo.lock()
            .expect("no panics while held")
            .insert(key, (table.clone(), shapes));
        Ok(table)
    }

    /// The key of the record of the grid over `range` ([`grid_key`]) and the photon policy of
    /// its tables.
    fn record_key(&self, range: [[f32; 2]; 3]) -> Result<(String, PhotonPolicy), MultipoleError> {
        let (params, media) = self.node(range.map(|[lo, _]| lo))?;
        let (node, photons) = first_table_key(
            &params,
            &media,
            self.method,
            self.shape_escapes,
            self.fidelity,
        )?;
        let refinement: Vec<f64> = [
            MAX_NODES_PER_AXIS as f64,
            MAX_GRID_TABLES as f64,
            MAX_PROBED_CELLS as f64,
        ]
        .into_iter()
        .chain(AXIS_KNEES.map(|k| k.map_or(-1.0, f64::from)))
        .chain(ERROR_NM.map(f64::from))
        .collect();
        let key = grid_key(
            &node,
            photons,
            self.shape_escapes,
            range,
            self.target,
            &refinement,
        );
        Ok((key, photons))
    }
}

/// What the cache keeps of a grid: its node counts per axis, its measured error and the shapes
/// each node's table was chosen with (C_m fastest).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct GridRecord {
    nodes: [u32; 3],
    max_error: f32,
    shapes: Vec<Shapes>,
}

impl GridRecord {
    /// The record of `grid`, whose tables and their shapes are in `memo`.
    fn of(grid: &ProfileGrid, memo: &Memo) -> Self {
        let memo = memo.lock().expect("no panics while held");
        Self {
            nodes: grid.axes().clone().map(|a| a.len() as u32),
            max_error: grid.max_error,
            shapes: node_points(grid.axes())
                .iter()
                .map(|p| memo[&p.map(f32::to_bits)].1)
                .collect(),
        }
    }

    /// The node counts when the refinement over `range` could have chosen them (1 on a
    /// one-value axis, else 2^k + 1 up to [`MAX_NODES_PER_AXIS`], at most [`MAX_GRID_TABLES`]
    /// in all), the error is a number ≥ 0 and each node's shapes are ones `settings`' photon
    /// policy `photons` can choose; else `None`.
    fn nodes_within(
        &self,
        range: [[f32; 2]; 3],
        settings: &GridSettings<'_>,
        photons: PhotonPolicy,
    ) -> Option<[usize; 3]> {
        let nodes = self.nodes.map(|n| n as usize);
        let fits = (0..3).all(|k| {
            let n = nodes[k];
            if range[k][1] > range[k][0] {
                (2..=MAX_NODES_PER_AXIS).contains(&n) && (n - 1).is_power_of_two()
            } else {
                n == 1
            }
        });
        let count = nodes.iter().product::<usize>();
        let shapes = self.shapes.len() == count
            && self
                .shapes
                .iter()
                .all(|&s| may_choose(settings.method, photons, settings.shape_escapes, s));
        (fits
            && count <= MAX_GRID_TABLES
            && self.max_error >= 0.0
            && self.max_error.is_finite()
            && shapes)
            .then_some(nodes)
    }
}

/// How a grid was found: its record's cache outcome and how many distinct tables it took.
#[derive(Debug, Clone, PartialEq)]
pub struct GridLoad {
    /// The record: a hit reads only the grid's own tables; otherwise the refinement ran.
    pub record: CacheOutcome,
    /// Tables read or built: the grid's nodes, plus on a refinement the coarser grids' and the
    /// probed cells' centres.
    pub tables: usize,
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
/// [`MAX_GRID_TABLES`] tables; the resolution chosen before with the same inputs is read from
/// the disk cache ([`profile_grid_traced`]).
pub fn profile_grid(
    settings: &GridSettings<'_>,
    range: [[f32; 2]; 3],
) -> Result<ProfileGrid, MultipoleError> {
    profile_grid_traced(settings, range).map(|(grid, _)| grid)
}

/// [`profile_grid`] and how it was found: the record of its resolution is kept in the cache
/// folder of the node tables (none under `--no-cache`).
pub fn profile_grid_traced(
    settings: &GridSettings<'_>,
    range: [[f32; 2]; 3],
) -> Result<(ProfileGrid, GridLoad), MultipoleError> {
    in_cache_folder(settings.fidelity, |dir, max_bytes| {
        profile_grid_in(settings, range, dir, max_bytes)
    })
}

/// [`profile_grid_traced`] with the record kept in `dir` (`None`: no record), the folder
/// bounded to `max_bytes`.
pub fn profile_grid_in(
    settings: &GridSettings<'_>,
    range: [[f32; 2]; 3],
    dir: Option<&Path>,
    max_bytes: u64,
) -> Result<(ProfileGrid, GridLoad), MultipoleError> {
    let memo: Memo = Mutex::new(HashMap::new());
    let Some(dir) = dir else {
        let grid = refine(settings, range, &memo)?;
        let tables = memo.lock().expect("no panics while held").len();
        let record = CacheOutcome::Off;
        return Ok((grid, GridLoad { record, tables }));
    };
    let (key, photons) = settings.record_key(range)?;
    let (record, outcome) = cache::load_or_build(Some(dir), max_bytes, &key, || {
        refine(settings, range, &memo).map(|grid| GridRecord::of(&grid, &memo))
    })?;
    let (grid, outcome) = match (record.nodes_within(range, settings, photons), outcome) {
        (Some(nodes), outcome) => {
            let axes = node_axes(range, nodes);
            let tables = node_tables(settings, &memo, &axes, Some(&record.shapes))?;
            (ProfileGrid::new(axes, tables, record.max_error), outcome)
        }
        (None, outcome) => {
            let grid = refine(settings, range, &memo)?;
            let record = GridRecord::of(&grid, &memo);
            let outcome = match (cache::store(dir, max_bytes, &key, &record), outcome) {
                (Err(why), _) => CacheOutcome::Unwritten(cache::entry_path(dir, &key), why),
                (Ok(path), CacheOutcome::Hit(_)) => {
                    CacheOutcome::Rebuilt(path, "nodes or shapes out of range")
                }
                (Ok(_), other) => other,
            };
            (grid, outcome)
        }
    };
    let tables = memo.lock().expect("no panics while held").len();
    Ok((
        grid,
        GridLoad {
            record: outcome,
            tables,
        },
    ))
}

/// The refinement of [`profile_grid`], every table through `memo`.
fn refine(
    settings: &GridSettings<'_>,
    range: [[f32; 2]; 3],
    memo: &Memo,
) -> Result<ProfileGrid, MultipoleError> {
    let mut nodes = range.map(|[lo, hi]| if hi > lo { 2 } else { 1 });
    loop {
        let axes = node_axes(range, nodes);
        let tables = node_tables(settings, memo, &axes, None)?;
        let mut grid = ProfileGrid::new(axes.clone(), tables, 0.0);
        let centres = cell_centres(&axes);
        let step = centres.len().div_ceil(MAX_PROBED_CELLS).max(1);
        let probed: Vec<[f32; 3]> = centres.into_iter().step_by(step).collect();
        let errors = probed
            .par_iter()
            .map(|&p| {
                let direct = settings.table(memo, p, None)?;
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

/// The node values of the grid over `range` with `nodes` nodes per axis: even in each axis's
/// warped coordinate, the ends exactly `lo` and `hi`.
pub(super) fn node_axes(range: [[f32; 2]; 3], nodes: [usize; 3]) -> [Vec<f32>; 3] {
    std::array::from_fn(|k| {
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
                _ => {
                    unwarp(AXIS_KNEES[k], wl + (wh - wl) * i as f32 / (n - 1) as f32).clamp(lo, hi)
                }
            })
            .collect()
    })
}

/// The parameters of every node of `axes`, C_m fastest.
pub(super) fn node_points(axes: &[Vec<f32>; 3]) -> Vec<[f32; 3]> {
    (0..axes[2].len())
        .flat_map(|c| {
            (0..axes[1].len()).flat_map(move |b| (0..axes[0].len()).map(move |a| [a, b, c]))
        })
        .map(|[a, b, c]| [axes[0][a], axes[1][b], axes[2][c]])
        .collect()
}

/// The table of every node of `axes`, C_m fastest; with each node's shapes `known` from a
/// record.
fn node_tables(
    settings: &GridSettings<'_>,
    memo: &Memo,
    axes: &[Vec<f32>; 3],
    known: Option<&[Shapes]>,
) -> Result<Vec<Arc<ProfileTable>>, MultipoleError> {
    let points = node_points(axes);
    (0..points.len())
        .into_par_iter()
        .map(|i| settings.table(memo, points[i], known.map(|k| k[i])))
        .collect()
}

/// The centre of every cell of the grid with node values `axes`, midway in each axis's warped
/// coordinate (a one-node axis keeps its node).
pub(super) fn cell_centres(axes: &[Vec<f32>; 3]) -> Vec<[f32; 3]> {
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

#[cfg(test)]
mod tests {
    use super::*;
    use skin_optics::Preset;

    fn nodes(grid: &ProfileGrid) -> usize {
        grid.axes().iter().map(Vec::len).product()
    }

    /// The grid a record gives is the refinement's, bit for bit.
    fn assert_same(a: &ProfileGrid, b: &ProfileGrid) {
        assert_eq!(a.axes(), b.axes());
        assert_eq!(a.max_error.to_bits(), b.max_error.to_bits());
        assert!(a.tables().iter().zip(b.tables()).all(|(x, y)| x == y));
    }

    /// A second load reads the recorded resolution and only the grid's own tables (no coarser
    /// grid, no cell centre); a corrupted record, another grid's record under this key's name
    /// and a record whose node counts the refinement could not have chosen are each refined
    /// again and rewritten.
    #[test]
    fn a_grid_record_is_reused_and_a_bad_one_refined_again() {
        let dir = tempfile::tempdir().unwrap();
        let d = Some(dir.path());
        let max = cache::DEFAULT_MAX_BYTES;
        let params = SkinParams::preset(Preset::Light);
        // The node tables themselves are built every time: only the record is cached here.
        let fidelity = FidelityKnobs {
            wavelength_step_nm: Some(20.0),
            cache: false,
            ..FidelityKnobs::default()
        };
        let settings = |target: f32| GridSettings {
            params: &params,
            phase_g: multipole::DEFAULT_G,
            surface: multipole::Surface::Fresnel,
            method: Method::Multipole,
            shape_escapes: None,
            fidelity: &fidelity,
            target,
        };
        let range = [[0.02, 0.3], [0.5, 0.5], [0.01, 0.01]];
        let s = settings(0.05);
        let (fresh, load) = profile_grid_in(&s, range, d, max).unwrap();
        assert!(matches!(load.record, CacheOutcome::Built(_)), "{load:?}");
        assert!(nodes(&fresh) > 2, "one refinement step at least");
        assert!(load.tables > nodes(&fresh), "{load:?}");
        let (again, load) = profile_grid_in(&s, range, d, max).unwrap();
        assert!(matches!(load.record, CacheOutcome::Hit(_)), "{load:?}");
        assert_eq!(load.tables, nodes(&fresh));
        assert_same(&again, &fresh);

        let path = cache::entry_path(dir.path(), &s.record_key(range).unwrap().0);
        let good = std::fs::read(&path).unwrap();
        let mut flipped = good.clone();
        *flipped.last_mut().unwrap() ^= 0x10;
        let coarse = settings(f32::MAX);
        profile_grid_in(&coarse, range, d, max).unwrap();
        let other = std::fs::read(cache::entry_path(
            dir.path(),
            &coarse.record_key(range).unwrap().0,
        ))
        .unwrap();
        for (bytes, why) in [(flipped, "checksum mismatch"), (other, "key mismatch")] {
            std::fs::write(&path, bytes).unwrap();
            let (grid, load) = profile_grid_in(&s, range, d, max).unwrap();
            assert_eq!(load.record, CacheOutcome::Rebuilt(path.clone(), why));
            assert!(load.tables > nodes(&fresh), "{load:?}");
            assert_same(&grid, &fresh);
        }
        let n = nodes(&fresh);
        let fixed = Shapes::Table(None);
        let bad_records = [
            ([64, 1, 1], vec![fixed; 64]),
            ([4, 1, 1], vec![fixed; 4]),
            ([5, 3, 1], vec![fixed; 15]),
            ([n as u32, 1, 1], vec![fixed; n - 1]),
            ([n as u32, 1, 1], vec![Shapes::Table(Some(50_000)); n]),
        ];
        for (nodes_out, shapes) in bad_records {
            let bad = GridRecord {
                nodes: nodes_out,
                max_error: 0.0,
                shapes,
            };
            cache::store(dir.path(), max, &s.record_key(range).unwrap().0, &bad).unwrap();
            let (grid, load) = profile_grid_in(&s, range, d, max).unwrap();
            assert_eq!(
                load.record,
                CacheOutcome::Rebuilt(path.clone(), "nodes or shapes out of range")
            );
            assert_same(&grid, &fresh);
        }
        let (_, load) = profile_grid_in(&s, range, d, max).unwrap();
        assert!(matches!(load.record, CacheOutcome::Hit(_)), "{load:?}");
        let (grid, load) = profile_grid_in(&s, range, None, max).unwrap();
        assert_eq!(load.record, CacheOutcome::Off);
        assert_same(&grid, &fresh);
    }
}
