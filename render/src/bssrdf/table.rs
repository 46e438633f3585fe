//! Per-material radial profile tables for rendering: 2πr R(r) on one geometric radius grid per
//! material, one row per tabulation wavelength, each with its CDF, in f32 (docs/physics.md §8).
//!
//! The profiles themselves come from the owner, `multipole::SpectralProfiles` (`Method::Exact`:
//! adding-doubling totals with the exact shapes of the universal table, or layered Monte Carlo
//! shapes every [`RENDER_SHAPE_STEP_NM`]; `Method::Multipole`: [DJ05] multipole with frequency-domain stacking,
//! [DJ06] two-layer skin); this module only re-tabulates them for speed and interpolates across
//! wavelength for the hero wavelengths of a path.
//!
//! # Interpolation and sampling
//! Within a row the density p(r) = 2πr R(r) is linear in r between grid radii (rising linearly
//! from p(0) = 0 below the first radius), so the CDF is piecewise quadratic and is inverted exactly,
//! and `eval` returns R = p / (2πr) from the same interpolant: for one wavelength, R(r) and the
//! sampling density are exactly proportional. Between two tabulation wavelengths λ_j, λ_{j+1} with
//! weight t the profile is the mixture (1 − t) R_j + t R_{j+1}, sampled exactly by first choosing
//! the row with probability ∝ its weighted energy.
//!
//! # Energy beyond the table
//! A row ends at the radius holding 99.9% of its energy (the multipole default); its R is scaled by
//! R_tot / ∫table so the table integrates to the model's total R_tot (exact, from q = 0): the 0.1%
//! tail is redistributed over the table instead of being lost.

use crate::spectrum::{
    GRID_10NM_NODES, GRID_10NM_STEP_NM, LAMBDA_MAX_NM, LAMBDA_MIN_NM, SampledWavelengths,
};
use multipole::{Method, MultipoleError, Profile, ProfileOptions, SpectralProfiles, sampling};
use serde::{Deserialize, Serialize};
use skin_optics::{SkinParams, WavelengthGrid};
use std::f32::consts::PI;

/// Wavelength step between Monte Carlo shapes in the render's tables, nm (rows between mix the
/// neighbouring shapes; each keeps its exact total): 40 nm would add up to 2% to the light skin's
/// worst shape error.
pub const RENDER_SHAPE_STEP_NM: f64 = 20.0;

/// Smallest radius of the grid, mm (matches the multipole tables' first radius).
pub const R_MIN_MM: f32 = 1e-3;
/// Most radii a table sized from an error target may have.
pub const MAX_RADII: usize = 512;

/// Knobs of a [`ProfileTable`].
#[derive(Debug, Clone, PartialEq)]
pub struct TableOptions {
    /// First tabulation wavelength, nm.
    pub from_nm: f64,
    /// Last tabulation wavelength, nm.
    pub to_nm: f64,
    /// Wavelength step, nm (profiles are linearly interpolated between steps).
    pub step_nm: f64,
    /// Radii of the common geometric grid (≥ 8), or with `radial_error` the fewest radii from 16
    /// up (doubling, at most [`MAX_RADII`]) that meet it.
    pub radii: usize,
    /// Energy left beyond each row's end, a fraction of its total in (0, 0.1] (`None`: each
    /// profile's own extent, 99.9% of its energy; docs/physics.md §16).
    pub energy_tolerance: Option<f64>,
    /// Interpolation error target of the radius grid (energy-weighted, a fraction of the total in
    /// (0, 0.1]; `None`: exactly `radii` radii; docs/physics.md §16).
    pub radial_error: Option<f64>,
    /// Knobs of each profile: the multipole's, and the exact method's shape (default: the universal
    /// table; a Monte Carlo shape is traced every [`RENDER_SHAPE_STEP_NM`]).
    pub profile: ProfileOptions,
}

impl Default for TableOptions {
    fn default() -> Self {
        Self {
            from_nm: f64::from(LAMBDA_MIN_NM),
            to_nm: f64::from(LAMBDA_MAX_NM),
            step_nm: 10.0,
            radii: 128,
            energy_tolerance: None,
            radial_error: None,
            profile: ProfileOptions {
                shape_step_nm: RENDER_SHAPE_STEP_NM,
                ..ProfileOptions::default()
            },
        }
    }
}

/// One tabulation wavelength.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct Row {
    /// p(r) = 2πr R(r) at the grid radii (mm⁻¹), scaled to integrate to `total`; only `len` used.
    p: Vec<f32>,
    /// Cumulative ∫₀^{r_i} p dr at the grid radii.
    cdf: Vec<f32>,
    /// Radii used: the row ends at grid index `len − 1`, its 99.9% energy radius.
    len: usize,
    /// ∫ p dr over the row (= the model's total diffuse reflectance R_tot).
    total: f32,
}

/// Radial profiles of one material at the tabulation wavelengths (f32, for the renderer).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(from = "StoredTable")]
pub struct ProfileTable {
    radii_mm: Vec<f32>,
    from_nm: f32,
    step_nm: f32,
    rows: Vec<Row>,
    /// Grid steps per unit of ln r: the radii are geometric, so ln(r / r₀) times this is the
    /// index of r's radius up to rounding.
    #[serde(skip)]
    steps_per_ln: f32,
}

/// A radius prepared for look-ups in any number of tables: r (at least half of [`R_MIN_MM`],
/// below which every profile is flat) and ln(r / [`R_MIN_MM`]), where every table's geometric
/// grid starts.
#[derive(Debug, Clone, Copy)]
pub struct TableRadius {
    r_mm: f32,
    ln_over_min: f32,
}

impl TableRadius {
    /// The radius `r_mm` (mm) prepared.
    #[must_use]
    #[inline]
    pub fn new(r_mm: f32) -> Self {
        let r_mm = r_mm.max(0.5 * R_MIN_MM);
        Self {
            r_mm,
            ln_over_min: (r_mm / R_MIN_MM).ln(),
        }
    }
}

/// What a [`ProfileTable`] stores: all but what is derived from it.
#[derive(Deserialize)]
struct StoredTable {
    radii_mm: Vec<f32>,
    from_nm: f32,
    step_nm: f32,
    rows: Vec<Row>,
}

impl From<StoredTable> for ProfileTable {
    fn from(t: StoredTable) -> Self {
        Self {
            steps_per_ln: steps_per_ln(&t.radii_mm),
            radii_mm: t.radii_mm,
            from_nm: t.from_nm,
            step_nm: t.step_nm,
            rows: t.rows,
        }
    }
}

/// Grid steps per unit of ln r of geometric radii `radii_mm` (0 for fewer than two).
fn steps_per_ln(radii_mm: &[f32]) -> f32 {
    match radii_mm {
        [first, .., last] if *first > 0.0 && last > first => {
            (radii_mm.len() - 1) as f32 / (last / first).ln()
        }
        _ => 0.0,
    }
}

/// A table resolved at one wavelength: its two rows, their weights and the mixed total R_tot, for
/// lookups at several radii without repeating the wavelength's interpolation.
#[derive(Debug, Clone, Copy)]
pub struct RowsAt<'a> {
    rows: [(&'a Row, f32); 2],
    total: f32,
}

impl RowsAt<'_> {
    /// The total diffuse reflectance R_tot at this wavelength, dimensionless.
    #[must_use]
    pub fn total(&self) -> f32 {
        self.total
    }
}

/// A wavelength between two rows of a table: lower row index and weight of the upper one. Tables
/// with the same rows ([`ProfileTable::same_rows`]) place a wavelength alike, so one place serves
/// them all.
#[derive(Debug, Clone, Copy)]
pub struct RowPlace {
    j: usize,
    t: f32,
}

impl RowPlace {
    /// The lower and upper row indices and the upper row's weight on a table of `rows` rows.
    #[must_use]
    #[inline]
    pub fn rows(self, rows: usize) -> (usize, usize, f32) {
        (self.j, (self.j + 1).min(rows - 1), self.t)
    }
}

impl ProfileTable {
    /// Compute the profiles of `skin` with `method` (in parallel across wavelengths) and tabulate them.
    pub fn build(
        skin: &SkinParams,
        method: Method,
        opts: &TableOptions,
    ) -> Result<Self, MultipoleError> {
        let grid = WavelengthGrid::new(opts.from_nm, opts.to_nm, opts.step_nm).map_err(|_| {
            MultipoleError::Profile(
                "table wavelength grid must lie in [250, 1000] nm with step ≥ 0.01 nm",
            )
        })?;
        let profiles = SpectralProfiles::new(skin, &grid, method, &opts.profile)?;
        let ends = super::extent::row_ends_mm(profiles.profiles(), opts.energy_tolerance)?;
        let radii = match opts.radial_error {
            None => opts.radii,
            Some(target) => super::extent::radii_for_error(profiles.profiles(), &ends, target)?,
        };
        Self::from_profiles_to(
            opts.from_nm as f32,
            opts.step_nm as f32,
            profiles.profiles(),
            &ends,
            radii,
        )
    }

    /// Tabulate `profiles` (one per wavelength, `from_nm` + i·`step_nm`) on `radii` geometric radii
    /// from [`R_MIN_MM`] to the largest 99.9% energy radius.
    pub fn from_profiles(
        from_nm: f32,
        step_nm: f32,
        profiles: &[Profile],
        radii: usize,
    ) -> Result<Self, MultipoleError> {
        let ends: Vec<f64> = profiles.iter().map(Profile::r_max_mm).collect();
        Self::from_profiles_to(from_nm, step_nm, profiles, &ends, radii)
    }

    /// [`ProfileTable::from_profiles`] with each row ending at its own radius `ends_mm` (mm, one per
    /// profile, each at most that profile's outer radius).
    pub fn from_profiles_to(
        from_nm: f32,
        step_nm: f32,
        profiles: &[Profile],
        ends_mm: &[f64],
        radii: usize,
    ) -> Result<Self, MultipoleError> {
        if profiles.is_empty()
            || ends_mm.len() != profiles.len()
            || !(8..=4096).contains(&radii)
            || step_nm.is_nan()
            || step_nm <= 0.0
        {
            return Err(MultipoleError::Profile(
                "need ≥ 1 profile with one end each, 8 to 4096 radii and a positive wavelength step",
            ));
        }
        let r_out = ends_mm.iter().copied().fold(0.0, f64::max) as f32;
        if r_out.is_nan() || r_out <= R_MIN_MM || !r_out.is_finite() {
            return Err(MultipoleError::Profile(
                "profile outer radius must exceed 1e-3 mm",
            ));
        }
        let ratio = (r_out / R_MIN_MM).ln() / (radii - 1) as f32;
        let mut radii_mm: Vec<f32> = (0..radii)
            .map(|i| R_MIN_MM * (ratio * i as f32).exp())
            .collect();
        radii_mm[radii - 1] = r_out;
        let rows = profiles
            .iter()
            .zip(ends_mm)
            .map(|(pr, &end)| {
                let r_end = end as f32;
                // First grid radius at or beyond this profile's own outer radius.
                let len = (radii_mm.partition_point(|&r| r < r_end) + 1).min(radii);
                let mut p: Vec<f32> = radii_mm[..len]
                    .iter()
                    .map(|&r| {
                        (2.0 * std::f64::consts::PI * f64::from(r) * pr.eval(f64::from(r))) as f32
                    })
                    .collect();
                let cdf = sampling::cumulative(&radii_mm, &p);
                let integral = cdf[len - 1];
                let total = pr.total() as f32;
                if integral.is_nan() || integral <= 0.0 || !total.is_finite() {
                    return Err(MultipoleError::Profile(
                        "profile has no energy on the table",
                    ));
                }
                let scale = total / integral;
                p.iter_mut().for_each(|v| *v *= scale);
                let cdf = sampling::cumulative(&radii_mm, &p);
                Ok(Row { p, cdf, len, total })
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Self {
            steps_per_ln: steps_per_ln(&radii_mm),
            radii_mm,
            from_nm,
            step_nm,
            rows,
        })
    }

    /// Number of tabulation wavelengths.
    #[must_use]
    pub fn wavelengths(&self) -> usize {
        self.rows.len()
    }

    /// The common radius grid, mm.
    #[must_use]
    pub fn radii_mm(&self) -> &[f32] {
        &self.radii_mm
    }

    fn lerp(&self, nm: f32) -> RowPlace {
        let x = ((nm - self.from_nm) / self.step_nm).clamp(0.0, (self.rows.len() - 1) as f32);
        let j = (x as usize).min(self.rows.len().saturating_sub(2));
        RowPlace {
            j,
            t: if self.rows.len() == 1 {
                0.0
            } else {
                x - j as f32
            },
        }
    }

    /// The rows and weights mixed at `nm`.
    fn mix(&self, nm: f32) -> [(&Row, f32); 2] {
        self.mix_at(self.lerp(nm))
    }

    #[inline]
    fn mix_at(&self, l: RowPlace) -> [(&Row, f32); 2] {
        let (lower, upper, t) = l.rows(self.rows.len());
        [(&self.rows[lower], 1.0 - t), (&self.rows[upper], t)]
    }

    /// Whether `other` has the same tabulation wavelengths (so places on the rows are shared).
    #[must_use]
    pub fn same_rows(&self, other: &Self) -> bool {
        self.rows.len() == other.rows.len()
            && self.from_nm == other.from_nm
            && self.step_nm == other.step_nm
    }

    /// R_tot of each tabulation row, dimensionless.
    pub fn row_totals(&self) -> impl Iterator<Item = f32> + '_ {
        self.rows.iter().map(|row| row.total)
    }

    /// Whether the rows are the path's 10-nm grid (380–780 nm every 10 nm, the default).
    #[inline]
    fn on_10nm_grid(&self) -> bool {
        self.rows.len() == GRID_10NM_NODES
            && self.from_nm == LAMBDA_MIN_NM
            && self.step_nm == GRID_10NM_STEP_NM
    }

    /// The model's total diffuse reflectance R_tot at `nm` (per unit flux entering), dimensionless.
    #[must_use]
    pub fn total(&self, nm: f32) -> f32 {
        self.at(nm).total
    }

    /// The table resolved at `nm` (for [`ProfileTable::eval_each`]).
    #[must_use]
    pub fn at(&self, nm: f32) -> RowsAt<'_> {
        Self::rows_at(self.mix(nm))
    }

    /// [`Self::at`] the path's wavelength `k` (on the 10-nm grid its row was found once per path).
    #[must_use]
    #[inline]
    pub fn at_lane(&self, wl: &SampledWavelengths, k: usize) -> RowsAt<'_> {
        self.at_place(self.place_lane(wl, k))
    }

    /// Where the path's wavelength `k` falls on the rows (on the 10-nm grid, found once per path).
    #[must_use]
    #[inline]
    pub fn place_lane(&self, wl: &SampledWavelengths, k: usize) -> RowPlace {
        if !self.on_10nm_grid() {
            return self.lerp(wl.nm(k));
        }
        let at = wl.on_10nm(k);
        RowPlace {
            j: at.index(),
            t: at.weight(),
        }
    }

    /// The table resolved at a wavelength placed on its rows ([`Self::place_lane`] of this table
    /// or of one with the same rows).
    #[must_use]
    #[inline]
    pub fn at_place(&self, place: RowPlace) -> RowsAt<'_> {
        Self::rows_at(self.mix_at(place))
    }

    #[inline]
    fn rows_at(rows: [(&Row, f32); 2]) -> RowsAt<'_> {
        RowsAt {
            rows,
            total: rows.iter().map(|(row, w)| w * row.total).sum(),
        }
    }

    /// Outer radius of the profile at `nm` (its 99.9% energy radius on the grid), mm.
    #[must_use]
    pub fn r_max_mm(&self, nm: f32) -> f32 {
        self.mix(nm)
            .iter()
            .filter(|(_, w)| *w > 0.0)
            .map(|(row, _)| self.radii_mm[row.len - 1])
            .fold(0.0, f32::max)
    }

    /// The largest radius over the rows holding the fraction `frac` of each row's energy, mm.
    #[must_use]
    pub fn largest_radius_for_energy_mm(&self, frac: f32) -> f32 {
        self.rows
            .iter()
            .map(|row| self.invert(row, frac.clamp(0.0, 1.0) * row.total))
            .fold(0.0, f32::max)
    }

    /// The radius holding the fraction `frac` of the profile's *luminance* under D65, mm: the
    /// rows' energies within r weighted by ȳ(λ)·D65(λ) and summed, E_Y(r) = Σ_λ ȳ D65 ∫₀^r p_λ,
    /// and r where E_Y(r) = frac · E_Y(∞) (docs/physics.md §16.3). It is the blur radius that the
    /// image's luminance — and so its error — sees, where [`ProfileTable::largest_radius_for_energy_mm`]
    /// is the widest row's, set by the red end that the eye barely weighs. Between grid radii
    /// E_Y is taken as linear (the rows' cumulative energies are tabulated on the shared grid).
    #[must_use]
    pub fn luminance_radius_for_energy_mm(&self, frac: f32) -> f32 {
        let weights: Vec<f64> = (0..self.rows.len())
            .map(|j| {
                let nm = f64::from(self.from_nm + j as f32 * self.step_nm);
                skin_optics::color::cie_xyz_bar(nm)[1] * skin_optics::color::d65(nm)
            })
            .collect();
        let energy_at = |i: usize| -> f64 {
            self.rows
                .iter()
                .zip(&weights)
                .map(|(row, w)| w * f64::from(row.cdf[i.min(row.len - 1)]))
                .sum()
        };
        let n = self.radii_mm.len();
        let target = f64::from(frac.clamp(0.0, 1.0)) * energy_at(n - 1);
        if target.is_nan() || target <= 0.0 {
            return 0.0;
        }
        let mut below = 0.0;
        for i in 0..n {
            let e = energy_at(i);
            if e >= target {
                let r0 = if i == 0 { 0.0 } else { self.radii_mm[i - 1] };
                let t = ((target - below) / (e - below).max(f64::MIN_POSITIVE)) as f32;
                return r0 + t.clamp(0.0, 1.0) * (self.radii_mm[i] - r0);
            }
            below = e;
        }
        self.radii_mm[n - 1]
    }

    /// R(r) at `nm` and distance `r_mm`, mm⁻² (integrates to [`ProfileTable::total`] over the plane).
    #[must_use]
    pub fn eval(&self, nm: f32, r_mm: f32) -> f32 {
        self.eval_each(&[Some(self.at(nm))], r_mm)[0]
    }

    /// R(r) at `r_mm` of each resolved wavelength in `at` (0 for `None`), mm⁻²: at each the value
    /// of [`ProfileTable::eval`]. All rows share the radius grid, so one search serves them all
    /// (the profile lookups are a large share of a skin sample's time).
    #[must_use]
    pub fn eval_each<const N: usize>(&self, at: &[Option<RowsAt<'_>>; N], r_mm: f32) -> [f32; N] {
        self.eval_each_at(at, TableRadius::new(r_mm))
    }

    /// [`ProfileTable::eval_each`] at a radius prepared once for several tables.
    #[must_use]
    #[inline]
    pub fn eval_each_at<const N: usize>(
        &self,
        at: &[Option<RowsAt<'_>>; N],
        radius: TableRadius,
    ) -> [f32; N] {
        let r = radius.r_mm;
        let radii = &self.radii_mm;
        let i = self.radius_index(radius);
        // Where r falls between two grid radii, shared by every row (beyond the grid every row
        // has ended; below its first radius the density rises linearly from 0).
        let t = (i > 0 && i < radii.len()).then(|| (r - radii[i - 1]) / (radii[i] - radii[i - 1]));
        at.map(|at| {
            at.map_or(0.0, |at| {
                let [(a, wa), (b, wb)] = at.rows;
                (wa * self.row_p_at(a, i, t, r) + wb * self.row_p_at(b, i, t, r)) / (2.0 * PI * r)
            })
        })
    }

    /// The index of the first grid radius ≥ `radius` (the grid's length when none is): guessed
    /// from the grid's geometric spacing from [`R_MIN_MM`] and corrected by comparison, so exact
    /// for any rounding and any grid.
    #[inline]
    fn radius_index(&self, radius: TableRadius) -> usize {
        let radii = &self.radii_mm;
        let n = radii.len();
        let r_mm = radius.r_mm;
        if r_mm.is_nan() {
            return 0;
        }
        // Truncation (a saturating cast) lands at most one index low; the loops correct it.
        let mut i = ((radius.ln_over_min * self.steps_per_ln) as usize).min(n);
        while i < n && radii[i] < r_mm {
            i += 1;
        }
        while i > 0 && radii[i - 1] >= r_mm {
            i -= 1;
        }
        i
    }

    /// Density p(r) = 2πr R(r) of one row at `r_mm`, mm⁻¹ (0 beyond the row), as
    /// `multipole::sampling::density` on the row, with the grid index `i` (the first grid
    /// radius ≥ `r_mm`) and the weight `t` of radius `i` against radius `i − 1` given.
    #[inline]
    fn row_p_at(&self, row: &Row, i: usize, t: Option<f32>, r_mm: f32) -> f32 {
        let radii = &self.radii_mm;
        if r_mm.is_nan() || r_mm < 0.0 || r_mm > radii[row.len - 1] {
            return 0.0;
        }
        match t {
            None => row.p[0] * r_mm / radii[0],
            Some(t) => row.p[i - 1] + t * (row.p[i] - row.p[i - 1]),
        }
    }

    /// Density of [`ProfileTable::sample_radius`] at `nm` per unit *area* of the plane at distance
    /// `r_mm`, mm⁻²: R(r) / R_tot.
    #[must_use]
    pub fn pdf_area(&self, nm: f32, r_mm: f32) -> f32 {
        let total = self.total(nm);
        if total > 0.0 {
            self.eval(nm, r_mm) / total
        } else {
            0.0
        }
    }

    /// A radius with density ∝ 2πr R(r) at `nm` from uniform `u` in [0, 1), mm.
    #[must_use]
    pub fn sample_radius(&self, nm: f32, u: f32) -> f32 {
        let [(a, wa), (b, wb)] = self.mix(nm);
        let (ea, eb) = (wa * a.total, wb * b.total);
        // Choose the row by its share of the mixture's energy, then reuse u within the row.
        let pa = if ea + eb > 0.0 { ea / (ea + eb) } else { 1.0 };
        let (row, u) = if u < pa {
            (a, u / pa)
        } else {
            (b, ((u - pa) / (1.0 - pa)).min(1.0))
        };
        self.invert(row, u.clamp(0.0, 1.0) * row.total)
    }

    /// The radius of `row` where its cumulative energy reaches `target`.
    fn invert(&self, row: &Row, target: f32) -> f32 {
        let n = row.len;
        sampling::invert(&self.radii_mm[..n], &row.p[..n], &row.cdf[..n], target)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use skin_optics::Preset;

    fn light_table() -> ProfileTable {
        ProfileTable::build(
            &SkinParams::preset(Preset::Light),
            Method::default(),
            &TableOptions::default(),
        )
        .unwrap()
    }

    /// One grid search for both mixed rows gives R(r) bit for bit as the piecewise-linear density
    /// of each row on its own (`multipole::sampling::density`), at radii on, between and beyond
    /// the grid nodes and below the first one.
    #[test]
    fn eval_is_the_mix_of_each_rows_density() {
        let t = light_table();
        let radii = t.radii_mm().to_vec();
        let mut rs: Vec<f32> = radii.clone();
        rs.extend(radii.windows(2).map(|w| 0.3 * w[0] + 0.7 * w[1]));
        rs.extend([0.0, 0.25 * R_MIN_MM, 1.5 * radii[radii.len() - 1], 1e3]);
        for nm in [380.0f32, 455.0, 560.0, 633.3, 780.0] {
            let [(a, wa), (b, wb)] = t.mix(nm);
            for &r_mm in &rs {
                let r = r_mm.max(0.5 * R_MIN_MM);
                let dens = |row: &Row| sampling::density(&radii[..row.len], &row.p[..row.len], r);
                let want = (wa * dens(a) + wb * dens(b)) / (2.0 * PI * r);
                assert_eq!(
                    t.eval(nm, r_mm).to_bits(),
                    want.to_bits(),
                    "{nm} nm, {r_mm} mm"
                );
            }
        }
    }

    /// The radius index guessed from the geometric spacing is the binary search's at every grid
    /// radius, just either side of it and between, and a table read back from its stored form
    /// guesses alike.
    #[test]
    fn radius_index_is_the_binary_searchs() {
        let t = light_table();
        let radii = t.radii_mm().to_vec();
        let mut rs: Vec<f32> = radii.clone();
        for &r in &radii {
            rs.extend([r.next_down(), r.next_up(), 0.999 * r, 1.001 * r]);
        }
        rs.extend([0.0, 0.25 * R_MIN_MM, 2.0 * radii[radii.len() - 1]]);
        let stored: ProfileTable =
            serde_json::from_str(&serde_json::to_string(&t).unwrap()).unwrap();
        assert_eq!(stored, t);
        for r in rs {
            assert_eq!(
                t.radius_index(TableRadius::new(r)),
                radii.partition_point(|&x| x < r.max(0.5 * R_MIN_MM)),
                "{r} mm"
            );
        }
    }

    /// The table integrates to the model's R_tot at every tabulation wavelength and in between.
    #[test]
    fn table_integrates_to_the_model_total() {
        let skin = SkinParams::preset(Preset::Light);
        let t = light_table();
        for nm in [380.0f32, 455.0, 560.0, 633.3, 780.0] {
            let r_max = t.r_max_mm(nm);
            // Midpoint rule in ln r (the grid is geometric) of 2πr² R(r).
            let n = 20_000;
            let (lo, hi) = ((0.5 * R_MIN_MM).ln(), r_max.ln());
            let h = (hi - lo) / n as f32;
            let mut s: f64 = (0..n)
                .map(|i| {
                    let r = (lo + (i as f32 + 0.5) * h).exp();
                    f64::from(2.0 * PI * r * r * t.eval(nm, r) * h)
                })
                .sum();
            // Below 0.5 µm: R is constant there, ∫ 2πr R dr = π r² R.
            s += f64::from(PI * (0.5 * R_MIN_MM).powi(2) * t.eval(nm, 0.0));
            let total = f64::from(t.total(nm));
            assert!(
                (s - total).abs() < 2e-3 * total,
                "{nm} nm: ∫ = {s}, total {total}"
            );
            // ...and the total is the multipole's (at tabulation wavelengths exactly).
            if (nm - 380.0) % 10.0 == 0.0 {
                let want = multipole::skin::total_reflectance(
                    &skin,
                    skin_optics::Wavelength::new(f64::from(nm)).unwrap(),
                    Method::default(),
                )
                .unwrap();
                assert!(
                    (total - want).abs() < 1e-5 * want,
                    "{nm}: {total} vs {want}"
                );
            }
        }
    }

    /// Sampling inverts the CDF: dr/du = 1 / pdf_r(r) with pdf_r = 2πr · pdf_area.
    #[test]
    fn sampling_matches_the_pdf() {
        // The multipole's smooth rows: a finite difference of u ↦ r across one of the Monte Carlo
        // shape's kinks (its density is piecewise linear on ≈ 15 nodes per decade) misses by a few %.
        let t = ProfileTable::build(
            &SkinParams::preset(Preset::Light),
            Method::Multipole,
            &TableOptions::default(),
        )
        .unwrap();
        // At tabulation wavelengths (between them the row is chosen first, so u ↦ r is not one CDF).
        for nm in [420.0f32, 580.0, 700.0] {
            for u in [0.01f32, 0.2, 0.45, 0.8, 0.97] {
                let du = 1e-3;
                let (r0, r1) = (t.sample_radius(nm, u), t.sample_radius(nm, u + du));
                let rm = 0.5 * (r0 + r1);
                let pdf_r = 2.0 * PI * rm * t.pdf_area(nm, rm);
                let got = (r1 - r0) / du;
                assert!(
                    (got * pdf_r - 1.0).abs() < 0.02,
                    "{nm} nm u {u}: dr/du {got}, 1/pdf {}",
                    1.0 / pdf_r
                );
            }
        }
    }

    /// The luminance r99 against an independent quadrature of the same profiles: E_Y(r) =
    /// Σ_λ ȳ D65 ∫₀^r 2πr' R_λ(r') dr' by the midpoint rule on 20,000 steps of [`ProfileTable::eval`],
    /// within 1%; and it lies inside the rows' own r99 range, below the widest (red) row's, since
    /// the light skin's profile widens with wavelength where ȳ falls.
    #[test]
    fn luminance_r99_matches_a_quadrature_of_the_rows() {
        let t = light_table();
        let r_y = t.luminance_radius_for_energy_mm(0.99);
        let rows = t.rows.len();
        let nm = |j: usize| t.from_nm + j as f32 * t.step_nm;
        let w: Vec<f64> = (0..rows)
            .map(|j| {
                let l = f64::from(nm(j));
                skin_optics::color::cie_xyz_bar(l)[1] * skin_optics::color::d65(l)
            })
            .collect();
        let r_out = *t.radii_mm.last().unwrap();
        let steps = 20_000u32;
        let dr = f64::from(r_out) / f64::from(steps);
        let mut cum = vec![0.0f64];
        for k in 0..steps {
            let r = (f64::from(k) + 0.5) * dr;
            let y: f64 = w
                .iter()
                .enumerate()
                .map(|(j, wj)| wj * f64::from(t.eval(nm(j), r as f32)))
                .sum();
            cum.push(cum[cum.len() - 1] + 2.0 * std::f64::consts::PI * r * y * dr);
        }
        let target = 0.99 * cum[cum.len() - 1];
        let k = cum.iter().position(|&c| c >= target).unwrap();
        let r_ref = k as f64 * dr;
        assert!(
            (f64::from(r_y) / r_ref - 1.0).abs() < 0.01,
            "luminance r99 {r_y} mm against quadrature {r_ref} mm"
        );
        let largest = t.largest_radius_for_energy_mm(0.99);
        let smallest = t
            .rows
            .iter()
            .map(|row| t.invert(row, 0.99 * row.total))
            .fold(f32::INFINITY, f32::min);
        assert!(
            smallest < r_y && r_y < 0.6 * largest,
            "{smallest} < {r_y} < 0.6 × {largest}"
        );
    }

    #[test]
    fn rejects_bad_input() {
        assert!(ProfileTable::from_profiles(380.0, 10.0, &[], 64).is_err());
    }
}
