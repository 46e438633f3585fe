//! The oblique-incidence gain of a skin with chromophore maps over the box of parameters its
//! maps use (docs/physics.md §19.3, "The angular factor at each end"): one adding-doubling gain
//! per node, at a resolution chosen from the interpolation error measured against gains built
//! directly at the cells' centres, kept whole in the disk cache.

use super::FidelityKnobs;
use super::grid::{MAX_PROBED_CELLS, cell_centres, node_axes, node_points};
use super::tables::in_cache_folder;
use crate::bssrdf::{Directional, IncidenceGain, IncidenceGrid};
use crate::media::SkinMedia;
use multipole::MultipoleError;
use multipole::exact::adding_doubling::DEFAULT_QUADRATURE_POINTS;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use skin_io::cache;
use skin_optics::SkinParams;
use std::collections::HashMap;
use std::path::Path;
use std::sync::{Arc, Mutex};

/// Default target of the gain grid's interpolation error: the largest relative error of a(μ, λ)
/// or c(λ) at the cells' centres. The gain itself moves the lips' brightness by a few per cent
/// from the typical skin's (§19.3), so half a per cent leaves little of that.
pub const DEFAULT_INCIDENCE_ERROR: f32 = 0.005;

/// Most nodes per axis (2⁴ + 1): the refinement stops there whatever the error.
pub const MAX_INCIDENCE_NODES_PER_AXIS: usize = 17;

/// Version of what [`incidence_grid`] computes from its inputs: bump it whenever the same inputs
/// would give another grid.
const INCIDENCE_GRID_VERSION: u32 = 2;

/// What a node's gain is built from besides its parameters.
#[derive(Debug, Clone, Copy)]
pub struct IncidenceSettings<'a> {
    /// The material's other parameters (oxygenation, thickness, η, extensions).
    pub params: &'a SkinParams,
    /// Henyey–Greenstein g of both layers.
    pub phase_g: f64,
    /// The skin's surface, the boundary of the totals.
    pub surface: multipole::Surface,
    /// The material's angular factor (its T(μ) and split).
    pub directional: &'a Directional,
    /// The fidelity knobs (whether the disk cache is used).
    pub fidelity: &'a FidelityKnobs,
    /// Target of the interpolation error ([`DEFAULT_INCIDENCE_ERROR`]).
    pub target: f32,
}

/// What the cache keeps of a grid.
#[derive(Serialize, Deserialize)]
struct Stored {
    axes: [Vec<f32>; 3],
    /// Each node's gain and normalisation rows.
    gains: Vec<(IncidenceGain, Vec<f32>)>,
    max_error: f32,
}

impl Stored {
    fn of(grid: &IncidenceGrid) -> Self {
        Self {
            axes: grid.axes().clone(),
            gains: grid
                .nodes()
                .iter()
                .filter_map(|d| Some((d.incidence()?.clone(), d.normalisation_rows()?.to_vec())))
                .collect(),
            max_error: grid.max_error,
        }
    }
}

/// Gains built so far, keyed by their parameters' bits.
type Memo = Mutex<HashMap<[u32; 3], Arc<IncidenceGain>>>;

impl IncidenceSettings<'_> {
    /// The layers of skin with parameters `p` = (C_m, β_m, C_h).
    fn media(&self, p: [f32; 3]) -> Result<SkinMedia, MultipoleError> {
        let params = self
            .params
            .with_melanin(f64::from(p[0]))?
            .with_eumelanin_blend(f64::from(p[1]))?
            .with_hemoglobin(f64::from(p[2]))?;
        Ok(SkinMedia::new(&params, self.phase_g)
            .map_err(|e| e.source)?
            .with_surface(self.surface))
    }

    /// The gain at `p`, built once.
    fn gain(&self, memo: &Memo, p: [f32; 3]) -> Result<Arc<IncidenceGain>, MultipoleError> {
        let key = p.map(f32::to_bits);
        if let Some(g) = memo.lock().map_err(|_| poisoned())?.get(&key) {
            return Ok(Arc::clone(g));
        }
        let g = Arc::new(IncidenceGain::build(
            self.media(p)?.every_10nm(),
            self.phase_g,
        )?);
        memo.lock()
            .map_err(|_| poisoned())?
            .insert(key, Arc::clone(&g));
        Ok(g)
    }

    /// The cache key: everything the grid depends on (the layers at the box's two extreme
    /// corners carry every other parameter and the chromophore data).
    fn key(&self, range: [[f32; 2]; 3]) -> Result<String, MultipoleError> {
        let lo = self.media(range.map(|r| r[0]))?;
        let hi = self.media(range.map(|r| r[1]))?;
        let rows = |m: &SkinMedia| format!("{:?}", m.every_10nm().collect::<Vec<_>>());
        Ok(format!(
            "incidence-grid v{INCIDENCE_GRID_VERSION} points {DEFAULT_QUADRATURE_POINTS} \
             max-nodes {MAX_INCIDENCE_NODES_PER_AXIS} probed {MAX_PROBED_CELLS} g {:?} \
             target {:?} box {range:?} directional {:?} low {} high {}",
            self.phase_g,
            self.target,
            self.directional,
            rows(&lo),
            rows(&hi),
        ))
    }
}

fn poisoned() -> MultipoleError {
    MultipoleError::InvalidOption {
        name: "incidence grid",
        value: f64::NAN,
        range: "a build that did not panic",
    }
}

/// The largest relative difference between the gains `a` and `b` over every row and angle, and
/// between their normalisations on `directional`.
fn gain_error(grid: &IncidenceGrid, p: [f32; 3], direct: &Directional) -> f32 {
    let Some(gain) = direct.incidence() else {
        return 0.0;
    };
    let corners = grid.corners(p);
    let mut worst = 0.0f32;
    for i in 0..gain.wavelengths() {
        let nm = IncidenceGain::row_nm(i);
        let wl = crate::spectrum::SampledWavelengths::fixed(nm);
        for &mu in gain.angles() {
            let want = direct.factor(mu, nm);
            if want > 0.0 {
                let got = corners.factors(mu, &wl).0[0];
                worst = worst.max((got / want - 1.0).abs());
            }
        }
        let c = corners.normalisations(&wl).0[0];
        worst = worst.max((c / direct.normalisation_at(nm) - 1.0).abs());
    }
    worst
}

/// The gain grid over the box `range` of (C_m, β_m, C_h): two nodes per varying axis, then 3,
/// 5, 9, 17 until the error at the cells' centres (up to 24 of them) is at most the target;
/// through the disk cache unless the fidelity knobs turn it off.
pub fn incidence_grid(
    settings: &IncidenceSettings<'_>,
    range: [[f32; 2]; 3],
) -> Result<IncidenceGrid, MultipoleError> {
    in_cache_folder(settings.fidelity, |dir, max_bytes| {
        incidence_grid_in(settings, range, dir, max_bytes)
    })
}

/// [`incidence_grid`] kept in the cache folder `dir` (`None`: built in memory), the folder bounded
/// to `max_bytes`. An entry whose axes the refinement could not have chosen over `range`, or
/// whose gains are not whole, is built again.
pub fn incidence_grid_in(
    settings: &IncidenceSettings<'_>,
    range: [[f32; 2]; 3],
    dir: Option<&Path>,
    max_bytes: u64,
) -> Result<IncidenceGrid, MultipoleError> {
    let key = settings.key(range)?;
    let (stored, _) = cache::load_or_build(dir, max_bytes, &key, || {
        refine(settings, range).map(|g| Stored::of(&g))
    })?;
    let counts = stored.axes.clone().map(|a| a.len());
    let chosen = counts.iter().zip(range).all(|(&n, [lo, hi])| {
        if hi > lo {
            (2..=MAX_INCIDENCE_NODES_PER_AXIS).contains(&n) && (n - 1).is_power_of_two()
        } else {
            n == 1
        }
    }) && node_axes(range, counts) == stored.axes;
    let gains = stored
        .gains
        .into_iter()
        .map(|(g, c)| (Arc::new(g), c))
        .collect();
    let grid = chosen
        .then(|| {
            IncidenceGrid::with_rows(stored.axes, settings.directional, gains, stored.max_error)
        })
        .flatten();
    match grid {
        Some(grid) => Ok(grid),
        None => {
            let grid = refine(settings, range)?;
            if let Some(dir) = dir {
                // A folder that cannot be written leaves the grid built in memory.
                let _ = cache::store(dir, max_bytes, &key, &Stored::of(&grid));
            }
            Ok(grid)
        }
    }
}

/// The refinement of [`incidence_grid`].
fn refine(
    settings: &IncidenceSettings<'_>,
    range: [[f32; 2]; 3],
) -> Result<IncidenceGrid, MultipoleError> {
    let memo = Memo::default();
    let mut nodes = range.map(|[lo, hi]| if hi > lo { 2 } else { 1 });
    loop {
        let axes = node_axes(range, nodes);
        let gains = node_points(&axes)
            .into_par_iter()
            .map(|p| settings.gain(&memo, p))
            .collect::<Result<Vec<_>, _>>()?;
        let mut grid = IncidenceGrid::new(axes.clone(), settings.directional, gains, 0.0);
        let centres = cell_centres(&axes);
        let step = centres.len().div_ceil(MAX_PROBED_CELLS).max(1);
        let probed: Vec<[f32; 3]> = centres.into_iter().step_by(step).collect();
        let errors = probed
            .par_iter()
            .map(|&p| {
                let direct = settings
                    .directional
                    .clone()
                    .with_incidence(settings.gain(&memo, p)?);
                Ok(gain_error(&grid, p, &direct))
            })
            .collect::<Result<Vec<f32>, MultipoleError>>()?;
        grid.max_error = errors.into_iter().fold(0.0, f32::max);
        if grid.max_error <= settings.target
            || nodes.iter().any(|&n| n >= MAX_INCIDENCE_NODES_PER_AXIS)
            || nodes == [1, 1, 1]
        {
            return Ok(grid);
        }
        nodes = nodes.map(|n| if n > 1 { 2 * n - 1 } else { 1 });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bssrdf::EnergySplit;
    use skin_optics::Preset;

    /// A grid is read back from the cache as it was stored: a valid entry under the key is
    /// returned as it stands (its recorded error shows it was read, not built), an entry whose axes
    /// the refinement could not have chosen is built again, and a grid read back equals the built
    /// one bit for bit.
    #[test]
    fn a_cached_grid_is_read_back_and_a_foreign_one_built_again() {
        let params = SkinParams::preset(Preset::Light);
        let lobe = brdf::TorranceSparrow::new(0.3, 0.25, 1.4).unwrap();
        let directional = Directional::new(lobe, EnergySplit::Fresnel);
        let fidelity = FidelityKnobs::default();
        let settings = IncidenceSettings {
            params: &params,
            phase_g: multipole::DEFAULT_G,
            surface: multipole::Surface::Fresnel,
            directional: &directional,
            fidelity: &fidelity,
            target: 0.05,
        };
        let range = [[0.02, 0.1], [0.5, 0.5], [0.01, 0.01]];
        let dir = tempfile::tempdir().unwrap();
        let max = cache::DEFAULT_MAX_BYTES;
        let built = incidence_grid_in(&settings, range, Some(dir.path()), max).unwrap();
        let rows = |g: &IncidenceGrid| -> Vec<Vec<f32>> {
            g.nodes()
                .iter()
                .map(|d| d.normalisation_rows().unwrap().to_vec())
                .collect()
        };
        let key = settings.key(range).unwrap();
        let mut marked = Stored::of(&built);
        marked.max_error = 0.0123;
        cache::store(dir.path(), max, &key, &marked).unwrap();
        let read = incidence_grid_in(&settings, range, Some(dir.path()), max).unwrap();
        assert_eq!(read.max_error, 0.0123);
        assert_eq!(read.axes(), built.axes());
        assert_eq!(rows(&read), rows(&built));
        let gains = |g: &IncidenceGrid| -> Vec<IncidenceGain> {
            g.nodes()
                .iter()
                .map(|d| d.incidence().unwrap().clone())
                .collect()
        };
        assert_eq!(gains(&read), gains(&built));
        let mut foreign = Stored::of(&built);
        foreign.axes[0] = vec![0.02, 0.05, 0.1];
        foreign.max_error = 0.0456;
        cache::store(dir.path(), max, &key, &foreign).unwrap();
        let rebuilt = incidence_grid_in(&settings, range, Some(dir.path()), max).unwrap();
        assert_eq!(rebuilt.max_error, built.max_error);
        assert_eq!(rebuilt.axes(), built.axes());
    }
}
