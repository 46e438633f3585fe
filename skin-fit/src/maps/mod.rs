//! Chromophore maps from an albedo texture: every texel's melanin C_m and blood C_h (with one
//! eumelanin blend β_m for the texture), the residual ΔE2000 and whether the model reaches the
//! texel (docs/physics.md §18).
//!
//! **Texels.** A texel is the skin's diffuse albedo: the model's diffuse reflectance (specular
//! excluded, the SCE of `skin fit`) under D65 with the CIE 1931 2° observer, as linear Rec.709
//! (sRGB primaries) with a perfect white diffuser at 1 — the colour `skin spectrum` prints,
//! through the same path ([`crate::ColourModel`], 400–700 nm every 10 nm).
//!
//! **Inversion.** A [`ForwardTable`] holds the exact model's CIELAB colour on a grid over
//! (C_m, β_m, C_h), built once and kept in the disk cache ([`skin_io::cache`]). For the texture's
//! β_m its slice is interpolated (cubic along β_m), and each texel is inverted on the slice's
//! bicubic interpolant: a seed from a grid over CIELAB, then damped Gauss–Newton steps minimising
//! the CIELAB distance (ΔE76) plus the tiny C_h prior of `skin fit` ([`PRIOR_WEIGHT_DE`]).
//! The reported residual is ΔE2000 ([`delta_e_2000_fast`]) between the texel and the fitted skin
//! on the interpolant; a texel is in gamut when it is at most [`IN_GAMUT_DE`].
//!
//! **β_m.** Three colour numbers per texel cannot pin three parameters well, so β_m is one value
//! per texture: given ([`Eumelanin::Fixed`]) or fitted ([`Eumelanin::Fit`]) as the β_m whose slice
//! passes closest to a sample of the texels (RMS of ΔE2000 capped at [`BETA_CAP_DE`], so hair and
//! other non-skin texels weigh no more than a poor skin fit). [`EumelaninSpread`] reports the β_m
//! range the data allow. [`Eumelanin::PerRegion`] lets it vary by region of the texture, with a
//! smoothness prior (module `regions`).
//!
//! **Exposure.** Every texel may be multiplied by gains on R, G, B first ([`Exposure`]), given or
//! fitted with β_m on the same sample; the residuals (reported and scored) compare the texel with
//! the fitted skin seen at the texture's own exposure (docs/physics.md §18, "Exposure").
//! The extended parameters of `skin fit --model` are one value per texture
//! ([`MapsModel::fit_extended`]).
//!
//! **Bad texels.** A non-finite, negative or huge component ([`MAX_TEXEL`]) is replaced (NaN by 0,
//! then clamped to [0, `MAX_TEXEL`]), fitted like any other and flagged out of gamut. Texels
//! outside the mask are not fitted: they get the median of the fitted maps, ΔE 0 and the flag 0.

mod delta_e;
mod edit;
mod extended;
mod invert;
mod regions;
mod table;
#[cfg(test)]
mod tests;
mod thin_epidermis;

pub use delta_e::delta_e_2000_fast;
pub use edit::{EDIT_SYNTAX, Edit, apply as apply_edits};
pub use extended::{EXTENDED_STEPS, ExtendedFit, ExtendedValue};
pub use invert::{Inverted, Inverter, LOOKUP_NODES, PRIOR_WEIGHT_DE};
pub use regions::{DEFAULT_SMOOTHNESS, REGION_SAMPLES, RegionSummary, Regions};
pub use table::{
    ForwardTable, MELANIN_KNEE, STEP_NM, Slice, TableSize, cache_key, hemoglobin_of_v,
    melanin_of_u, u_of_melanin, v_of_hemoglobin,
};
pub use thin_epidermis::{
    THIN_EPIDERMIS_MM, THIN_HEMOGLOBIN_RANGE, THIN_MIN_GAIN_DE, ThinEpidermis,
};

use crate::FitError;
use rayon::prelude::*;
use skin_io::cache::CacheOutcome;
use skin_optics::SkinParams;
use skin_optics::color::LinearSrgb;
use skin_optics::lab::Lab;
use std::path::PathBuf;

/// A texel is in gamut when the fitted skin reproduces it within this ΔE2000.
pub const IN_GAMUT_DE: f64 = 1.0;
/// Largest texel component accepted as is (linear albedo; a white diffuser is 1).
pub const MAX_TEXEL: f32 = 16.0;
/// ΔE2000 cap of one texel's contribution to the β_m objective.
pub const BETA_CAP_DE: f64 = 3.0;
/// Texels handed to one worker at a time (and the granularity of progress reports).
const CHUNK: usize = 1 << 14;

/// Why maps could not be made or edited.
#[derive(Debug, thiserror::Error)]
pub enum MapsError {
    /// An option or edit value outside its range.
    #[error("maps option {name} = {} outside {range}", skin_optics::echo::Num(*.value))]
    Option {
        /// The option.
        name: &'static str,
        /// The value given.
        value: f64,
        /// Its valid range.
        range: &'static str,
    },
    /// A per-texel input whose length is not the texture's.
    #[error("{what} has {found} values for {expected} texels")]
    Length {
        /// Which input.
        what: &'static str,
        /// Values given.
        found: usize,
        /// Texels in the texture.
        expected: usize,
    },
    /// An edit that does not parse.
    #[error("edit '{text}' is not one of {EDIT_SYNTAX}")]
    Edit {
        /// The text given.
        text: String,
    },
    /// The forward table could not be built.
    #[error("forward table: {0}")]
    Model(#[from] FitError),
}

/// How the texture's eumelanin blend β_m is chosen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Eumelanin {
    /// This β_m, in [0, 1].
    Fixed(f64),
    /// Fitted over the texels (module doc).
    Fit,
    /// One value per region of the texture, with a smoothness prior ([`Regions`]).
    PerRegion(Regions),
}

/// How the texture's exposure is chosen: a gain on each linear channel (R, G, B) of every texel
/// before the fit, for a photograph whose light level or white balance is not that of the D65
/// white the texels are relative to (module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Exposure {
    /// These gains on R, G and B, each in [`EXPOSURE_RANGE`] (1: the texels as given).
    Fixed([f64; 3]),
    /// One gain on all three channels, fitted with β_m over the texels: the gain whose maps
    /// pass closest to a sample of them.
    Auto,
    /// A gain per channel (exposure and white balance), fitted as [`Exposure::Auto`].
    WhiteBalance,
}

impl std::str::FromStr for Exposure {
    type Err = String;

    /// `auto`, `auto-rgb`, one gain `G` or three `R,G,B`, each in [`EXPOSURE_RANGE`] (the
    /// spelling of `skin maps --exposure`); an error says what was wrong and the valid forms.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "auto" => return Ok(Exposure::Auto),
            "auto-rgb" => return Ok(Exposure::WhiteBalance),
            _ => {}
        }
        let [lo, hi] = EXPOSURE_RANGE;
        let fields: Vec<&str> = s.split(',').collect();
        if fields.len() != 1 && fields.len() != 3 {
            return Err(format!(
                "'{}' is not G, R,G,B, auto or auto-rgb (gains in [0.125, 2])",
                skin_optics::echo::Text(s)
            ));
        }
        let mut gains = [0.0; 3];
        for (k, f) in fields.iter().enumerate() {
            let g: f64 = f.trim().parse().map_err(|_| {
                format!(
                    "'{}' is not a number (valid range [0.125, 2])",
                    skin_optics::echo::Text(f)
                )
            })?;
            if !(lo..=hi).contains(&g) {
                return Err(format!(
                    "gain {} outside [0.125, 2] (or auto, auto-rgb)",
                    skin_optics::echo::Num(g)
                ));
            }
            gains[k] = g;
        }
        if fields.len() == 1 {
            gains = [gains[0]; 3];
        }
        Ok(Exposure::Fixed(gains))
    }
}

/// Gains the exposure fit explores: 1/8 to 2 (three stops down, one up).
pub const EXPOSURE_RANGE: [f64; 2] = [0.125, 2.0];
/// Gain candidates of the exposure fit, evenly in log₂ g over [`EXPOSURE_RANGE`] (eighth stops).
const EXPOSURE_STEPS: usize = 33;

/// Whether texels are inverted through the inverse lookup grid ([`Inverter::invert_fast`]) or
/// each by the full inversion ([`Inverter::invert`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Lookup {
    /// The grid when there are more fitted texels than it has nodes (it costs one full
    /// inversion per node to build), else the full inversion.
    #[default]
    Auto,
    /// Always through the grid.
    Always,
    /// Always the full inversion.
    Never,
}

/// Knobs of [`fit_maps`]. `Default` gives the documented values.
#[derive(Debug, Clone, PartialEq)]
pub struct MapsOptions {
    /// β_m given or fitted (default fitted).
    pub eumelanin: Eumelanin,
    /// Nodes of the forward table (default 24 × 11 × 16).
    pub table: TableSize,
    /// Skin supplying everything not mapped (ρ_s, γ, thicknesses, η): default `skin fit`'s.
    pub base: SkinParams,
    /// Folder of the table cache; `None` builds the table in memory.
    pub cache_dir: Option<PathBuf>,
    /// Size limit of the cache folder, bytes ([`skin_io::cache::DEFAULT_MAX_BYTES`]).
    pub cache_max_bytes: u64,
    /// Texels sampled (evenly over the fitted ones) for the β_m fit, in [1, 10⁶] (default 4096).
    pub beta_samples: usize,
    /// β_m candidates evenly over [0, 1] in the fit, in [3, 101] (default 21: steps of 0.05).
    pub beta_steps: usize,
    /// β_m is allowed where the sample's RMS capped ΔE2000 is within this of the best (default 0.25).
    pub beta_tolerance_de: f64,
    /// The inverse lookup grid or the full inversion per texel (default [`Lookup::Auto`]).
    pub lookup: Lookup,
    /// The gain on every texel, given or fitted (default 1: the texels as given).
    pub exposure: Exposure,
    /// Epidermis thickness, mm, of the second skin that texels out of gamut are fitted again
    /// under (lip vermilion; module `thin_epidermis`), in [0.04, 0.3]; `None`: one skin for
    /// every texel (default [`THIN_EPIDERMIS_MM`]).
    pub thin_epidermis_mm: Option<f64>,
    /// The top of the C_h range of the thin-epidermis skin, in (0.001, 1] (default
    /// [`THIN_HEMOGLOBIN_RANGE`]'s 0.25; 0.1 gives it the texture's skin's range).
    pub thin_hemoglobin_max: f64,
}

impl Default for MapsOptions {
    fn default() -> Self {
        Self {
            eumelanin: Eumelanin::Fit,
            table: TableSize::default(),
            base: crate::FitOptions::default().base,
            cache_dir: None,
            cache_max_bytes: skin_io::cache::DEFAULT_MAX_BYTES,
            beta_samples: 4096,
            beta_steps: 21,
            beta_tolerance_de: 0.25,
            lookup: Lookup::Auto,
            exposure: Exposure::Fixed([1.0; 3]),
            thin_epidermis_mm: Some(THIN_EPIDERMIS_MM),
            thin_hemoglobin_max: THIN_HEMOGLOBIN_RANGE[1],
        }
    }
}

impl MapsOptions {
    /// Check every knob against its range.
    pub fn validate(&self) -> Result<(), MapsError> {
        let check = |name, value: f64, ok: bool, range| {
            if ok && value.is_finite() {
                Ok(())
            } else {
                Err(MapsError::Option { name, value, range })
            }
        };
        if let Eumelanin::Fixed(b) = self.eumelanin {
            check("eumelanin", b, (0.0..=1.0).contains(&b), "[0, 1]")?;
        }
        if let Eumelanin::PerRegion(r) = self.eumelanin {
            check(
                "eumelanin regions block",
                r.block as f64,
                (4..=4096).contains(&r.block),
                "[4, 4096] texels",
            )?;
            check(
                "eumelanin regions width",
                r.width as f64,
                r.width >= 1,
                "[1, ∞) texels",
            )?;
            check(
                "eumelanin smoothness",
                r.smoothness,
                r.smoothness >= 0.0,
                "[0, ∞) ΔE² per unit β_m²",
            )?;
        }
        if let Some(t) = self.thin_epidermis_mm {
            let [lo, hi] = crate::Parameter::EpidermisThickness.range();
            check(
                "thin_epidermis_mm",
                t,
                (lo..=hi).contains(&t),
                "[0.04, 0.3] mm",
            )?;
        }
        check(
            "thin_hemoglobin_max",
            self.thin_hemoglobin_max,
            self.thin_hemoglobin_max > THIN_HEMOGLOBIN_RANGE[0] && self.thin_hemoglobin_max <= 1.0,
            "(0.001, 1]",
        )?;
        if let Exposure::Fixed(gains) = self.exposure {
            let [lo, hi] = EXPOSURE_RANGE;
            for g in gains {
                check("exposure", g, (lo..=hi).contains(&g), "[0.125, 2]")?;
            }
        }
        for (name, n) in [
            ("table.melanin", self.table.melanin),
            ("table.eumelanin", self.table.eumelanin),
            ("table.hemoglobin", self.table.hemoglobin),
        ] {
            check(name, n as f64, (4..=256).contains(&n), "[4, 256] nodes")?;
        }
        check(
            "beta_samples",
            self.beta_samples as f64,
            (1..=1_000_000).contains(&self.beta_samples),
            "[1, 1000000]",
        )?;
        check(
            "beta_steps",
            self.beta_steps as f64,
            (3..=101).contains(&self.beta_steps),
            "[3, 101]",
        )?;
        check(
            "beta_tolerance_de",
            self.beta_tolerance_de,
            self.beta_tolerance_de >= 0.0,
            "[0, ∞)",
        )
    }
}

/// The range of a per-texture value (β_m, the exposure, an extended parameter) that the texels
/// allow: around the fit, where the sample's RMS capped ΔE2000 (linear between the candidates
/// tried) stays within `tolerance_de` of the best candidate's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FittedRange {
    /// Lowest allowed value.
    pub min: f64,
    /// Highest allowed value.
    pub max: f64,
    /// The tolerance, ΔE2000.
    pub tolerance_de: f64,
    /// RMS capped ΔE2000 of the sample at the fitted value.
    pub best_rms_de: f64,
}

/// The β_m range the texels allow.
pub type EumelaninSpread = FittedRange;

/// What a fit did, for the summary line.
#[derive(Debug, Clone, PartialEq)]
pub struct MapsSummary {
    /// Texels fitted (inside the mask).
    pub fitted: usize,
    /// Fitted texels in gamut (ΔE2000 ≤ [`IN_GAMUT_DE`]).
    pub in_gamut: usize,
    /// Texels whose value was replaced (non-finite, negative or above [`MAX_TEXEL`]).
    pub invalid: usize,
    /// Median ΔE2000 over the fitted texels (0 when none).
    pub median_de: f64,
    /// 95th percentile ΔE2000 over the fitted texels.
    pub p95_de: f64,
    /// Largest ΔE2000 over the fitted texels.
    pub max_de: f64,
    /// The β_m range the data allow (`None` when β_m was given or nothing was fitted).
    pub eumelanin_spread: Option<EumelaninSpread>,
    /// The gains on R, G and B applied to every texel before the fit.
    pub exposure: [f64; 3],
    /// The common gains the data allow (`None` unless [`Exposure::Auto`] fitted them).
    pub exposure_spread: Option<FittedRange>,
    /// β_m over the regions (`None` unless [`Eumelanin::PerRegion`]).
    pub regions: Option<RegionSummary>,
    /// Fitted texels whose skin has the thin epidermis ([`MapsOptions::thin_epidermis_mm`]).
    pub thin_epidermis: usize,
}

/// The maps of a texture, one value per texel (row-major, as the texels given).
#[derive(Debug, Clone, PartialEq)]
pub struct Maps {
    /// Melanin volume fraction C_m, [0, 0.5].
    pub melanin: Vec<f32>,
    /// Hemoglobin volume fraction C_h, [0.001, 0.1].
    pub hemoglobin: Vec<f32>,
    /// Eumelanin blend β_m of the whole texture, [0, 1] (with regions: their median).
    pub eumelanin: f64,
    /// β_m of every texel when it varies by region ([`Eumelanin::PerRegion`]).
    pub eumelanin_map: Option<Vec<f32>>,
    /// ΔE2000 between the texel and the fitted skin (0 outside the mask).
    pub delta_e: Vec<f32>,
    /// Whether the texel was fitted and reproduced within [`IN_GAMUT_DE`].
    pub in_gamut: Vec<bool>,
    /// Whether the texel was fitted (inside the mask).
    pub fitted: Vec<bool>,
    /// The texels fitted under the thin epidermis (`None` when none were).
    pub thin_epidermis: Option<ThinEpidermis>,
    /// Counts and residual statistics.
    pub summary: MapsSummary,
}

/// The forward table, loaded or built: fits texels and turns maps back into albedo.
#[derive(Debug, Clone)]
pub struct MapsModel {
    table: ForwardTable,
    outcome: CacheOutcome,
    /// Thin-epidermis tables loaded so far, by cache key (shared by clones).
    thin_tables: thin_epidermis::Tables,
}

/// Slots of the per-worker memo of recent texel values.
const MEMO_SLOTS: usize = 1 << 12;

/// The memo slot of a texel's bits (a multiplicative hash).
#[inline]
fn memo_slot(bits: [u32; 3]) -> usize {
    let h = (u64::from(bits[0])
        ^ u64::from(bits[1]).rotate_left(21)
        ^ u64::from(bits[2]).rotate_left(42))
    .wrapping_mul(0x9E37_79B9_7F4A_7C15);
    (h >> (64 - MEMO_SLOTS.trailing_zeros())) as usize
}

/// CIELAB (L*, a*, b*) of a linear Rec.709 texel, and whether it had to be replaced (module
/// doc): CIE 015 eqs 8.1–8.4 as [`Lab::from_xyz`], with the cube root by Halley's iteration.
#[inline]
#[must_use]
pub fn texel_lab(t: [f32; 3]) -> ([f64; 3], bool) {
    let bad = t
        .iter()
        .any(|c| !(c.is_finite() && (0.0..=MAX_TEXEL).contains(c)));
    let rgb = t.map(|c| {
        if c.is_nan() {
            0.0
        } else {
            f64::from(c.clamp(0.0, MAX_TEXEL))
        }
    });
    (lab_of_linear(rgb), bad)
}

/// CIELAB of linear Rec.709 `rgb` (non-negative): CIE 015 eqs 8.1–8.4 as [`Lab::from_xyz`], with
/// the cube root by Halley's iteration.
#[inline]
fn lab_of_linear(rgb: [f64; 3]) -> [f64; 3] {
    let xyz = LinearSrgb(rgb).to_xyz().0;
    let w = skin_optics::lab::d65_white().0;
    const DELTA3: f64 = (6.0 / 29.0) * (6.0 / 29.0) * (6.0 / 29.0);
    let f = |x: f64| {
        if x > DELTA3 {
            cbrt(x)
        } else {
            x / (3.0 * (6.0 / 29.0) * (6.0 / 29.0)) + 4.0 / 29.0
        }
    };
    let [fx, fy, fz] = [f(xyz[0] / w[0]), f(xyz[1] / w[1]), f(xyz[2] / w[2])];
    [116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)]
}

/// CIELAB of a fitted colour `lab` (found for texels scaled by `gain`) seen at the texture's own
/// exposure: its linear Rec.709 divided by the gains.
#[inline]
fn unscaled(lab: &[f64; 3], gain: [f64; 3]) -> [f64; 3] {
    let rgb = lab_of(*lab).to_xyz().to_linear_srgb().0;
    lab_of_linear(std::array::from_fn(|c| (rgb[c] / gain[c]).max(0.0)))
}

/// Cube root of a positive normal `x`: a first guess from the exponent bits (within 3.3 %), then
/// two Halley steps y ← y (y³ + 2x)/(2y³ + x), each cubing the relative error (to below 1e-13).
#[inline]
fn cbrt(x: f64) -> f64 {
    let mut y = f64::from_bits(x.to_bits() / 3 + 0x2A9F_7893_782D_A1CE);
    for _ in 0..2 {
        let y3 = y * y * y;
        y *= (y3 + 2.0 * x) / (2.0 * y3 + x);
    }
    y
}

#[inline]
fn lab_of(x: [f64; 3]) -> Lab {
    Lab {
        l: x[0],
        a: x[1],
        b: x[2],
    }
}

impl MapsModel {
    /// The table of `opts` from the cache, or built (about 5000 exact colours) and stored.
    pub fn load(opts: &MapsOptions) -> Result<Self, MapsError> {
        opts.validate()?;
        let key = cache_key(opts.table, &opts.base, crate::HEMOGLOBIN_RANGE);
        let build = || ForwardTable::build(opts.table, opts.base);
        let (table, outcome) = skin_io::cache::load_or_build(
            opts.cache_dir.as_deref(),
            opts.cache_max_bytes,
            &key,
            build,
        )?;
        if table.is_whole()
            && table.size() == opts.table
            && table.hemoglobin_range() == crate::HEMOGLOBIN_RANGE
        {
            return Ok(Self {
                table,
                outcome,
                thin_tables: thin_epidermis::Tables::default(),
            });
        }
        // A readable entry of the wrong shape: rebuilt, not trusted.
        Ok(Self {
            table: build()?,
            outcome: CacheOutcome::Off,
            thin_tables: thin_epidermis::Tables::default(),
        })
    }

    /// A model around a table already built.
    #[must_use]
    pub fn from_table(table: ForwardTable) -> Self {
        Self {
            table,
            outcome: CacheOutcome::Off,
            thin_tables: thin_epidermis::Tables::default(),
        }
    }

    /// What the cache did for the table.
    #[must_use]
    pub fn cache_outcome(&self) -> &CacheOutcome {
        &self.outcome
    }

    /// The forward table.
    #[must_use]
    pub fn table(&self) -> &ForwardTable {
        &self.table
    }

    /// Fit the maps of `texels` (linear Rec.709 diffuse albedo), only where `mask` is true if
    /// given. `progress` is called from worker threads with the number of texels just finished.
    pub fn fit(
        &self,
        texels: &[[f32; 3]],
        mask: Option<&[bool]>,
        opts: &MapsOptions,
        progress: &(dyn Fn(usize) + Sync),
    ) -> Result<Maps, MapsError> {
        opts.validate()?;
        if let Some(m) = mask
            && m.len() != texels.len()
        {
            return Err(MapsError::Length {
                what: "mask",
                found: m.len(),
                expected: texels.len(),
            });
        }
        let fitted: Vec<bool> = mask.map_or_else(|| vec![true; texels.len()], <[bool]>::to_vec);
        let shared = self.fit_shared(texels, &fitted, opts);
        let (beta, gain) = (shared.beta, shared.gain);
        let gain32 = gain.map(|g| g as f32);
        let unit_gain = gain == [1.0; 3];
        let count = fitted.iter().filter(|f| **f).count();
        let with_lookup = |texels: usize| match opts.lookup {
            Lookup::Always => true,
            Lookup::Auto => texels > LOOKUP_NODES,
            Lookup::Never => false,
        };
        // One inverter per β_m in use: the texture's, or each region's candidate.
        let (inverters, regions): (Vec<Inverter>, Option<regions::RegionFit>) = match opts.eumelanin
        {
            Eumelanin::PerRegion(r) => {
                let steps = opts.beta_steps;
                let betas: Vec<f64> = (0..steps).map(|i| i as f64 / (steps - 1) as f64).collect();
                let plain: Vec<Inverter> = betas
                    .par_iter()
                    .map(|&b| Inverter::new(self.table.slice(b)))
                    .collect();
                let fit = regions::fit_regions(
                    texels,
                    &fitted,
                    r,
                    &betas,
                    &plain,
                    gain,
                    opts.beta_tolerance_de,
                )?;
                let mut uses = vec![0usize; betas.len()];
                for (l, f) in fit.label_of_texel.iter().zip(&fitted) {
                    uses[usize::from(*l)] += usize::from(*f);
                }
                let inverters = plain
                    .into_iter()
                    .zip(&uses)
                    .map(|(inv, &u)| {
                        if u > 0 && with_lookup(u) {
                            Inverter::with_lookup(inv.slice().clone())
                        } else {
                            inv
                        }
                    })
                    .collect();
                (inverters, Some(fit))
            }
            _ => {
                let slice = self.table.slice(beta);
                let inv = if with_lookup(count) {
                    Inverter::with_lookup(slice)
                } else {
                    Inverter::new(slice)
                };
                (vec![inv], None)
            }
        };
        let labels: Option<&[u8]> = regions.as_ref().map(|r| r.label_of_texel.as_slice());
        let n = texels.len();
        let mut melanin = vec![0.0f32; n];
        let mut hemoglobin = vec![0.0f32; n];
        let mut delta_e = vec![0.0f32; n];
        let mut in_gamut = vec![false; n];
        let invalid = melanin
            .par_chunks_mut(CHUNK)
            .zip(hemoglobin.par_chunks_mut(CHUNK))
            .zip(delta_e.par_chunks_mut(CHUNK))
            .zip(in_gamut.par_chunks_mut(CHUNK))
            .zip(texels.par_chunks(CHUNK).zip(fitted.par_chunks(CHUNK)))
            .enumerate()
            .map(|(chunk, ((((m, h), de), g), (t, f)))| {
                let mut invalid = 0;
                // Textures decoded from 8- or 16-bit files repeat colours, mostly nearby: a
                // small direct-mapped memo of exact texel values skips the repeats.
                let mut memo = vec![None; MEMO_SLOTS];
                for k in 0..t.len() {
                    if !f[k] {
                        continue;
                    }
                    let label = labels.map_or(0, |l| l[chunk * CHUNK + k]);
                    let bits = t[k].map(f32::to_bits);
                    let slot = memo_slot(bits);
                    let (mk, hk, dk, bad) = match memo[slot] {
                        Some((b, l, out)) if b == bits && l == label => out,
                        _ => {
                            let (lab, bad) = texel_lab(scaled(t[k], gain32));
                            let inv = &inverters[usize::from(label)];
                            let r = inv.invert_fast(&lab);
                            // The residual at the texture's own exposure (module doc).
                            let (seen, fit) = if unit_gain {
                                (lab, r.lab)
                            } else {
                                (texel_lab(t[k]).0, unscaled(&r.lab, gain))
                            };
                            let out = (
                                melanin_of_u(r.u) as f32,
                                inv.slice().hemoglobin_of_v(r.v) as f32,
                                delta_e_2000_fast(&seen, &fit) as f32,
                                bad,
                            );
                            memo[slot] = Some((bits, label, out));
                            out
                        }
                    };
                    invalid += usize::from(bad);
                    m[k] = mk;
                    h[k] = hk;
                    de[k] = dk;
                    g[k] = !bad && f64::from(dk) <= IN_GAMUT_DE;
                }
                progress(t.len());
                invalid
            })
            .sum();
        // Texels out of gamut, fitted again under the thin epidermis (module `thin_epidermis`).
        let thin = match opts.thin_epidermis_mm {
            Some(mm) => {
                let candidates: Vec<usize> = (0..n)
                    .filter(|&k| fitted[k] && !in_gamut[k] && !texel_lab(texels[k]).1)
                    .collect();
                if candidates.is_empty() {
                    None
                } else {
                    let betas = regions
                        .as_ref()
                        .map_or_else(|| vec![beta], |r| r.betas.clone());
                    let (table, refits) = thin_epidermis::refit(
                        &self.thin_tables,
                        opts,
                        mm,
                        texels,
                        &candidates,
                        labels,
                        &betas,
                        gain,
                        &delta_e,
                    )?;
                    let mut flags = vec![false; n];
                    for &(k, m, h, de) in &refits {
                        melanin[k] = m;
                        hemoglobin[k] = h;
                        delta_e[k] = de;
                        in_gamut[k] = thin_epidermis::in_gamut(de);
                        flags[k] = true;
                    }
                    (!refits.is_empty()).then_some(ThinEpidermis {
                        epidermis_mm: mm,
                        texels: flags,
                        table,
                    })
                }
            }
            None => None,
        };
        let mut residuals: Vec<f32> = delta_e
            .iter()
            .zip(&fitted)
            .filter(|(_, f)| **f)
            .map(|(d, _)| *d)
            .collect();
        let median = |v: &mut Vec<f32>| -> f32 {
            if v.is_empty() {
                return 0.0;
            }
            let mid = v.len() / 2;
            *v.select_nth_unstable_by(mid, f32::total_cmp).1
        };
        let (fill_m, fill_h) = {
            let pick = |x: &[f32]| -> Vec<f32> {
                x.iter()
                    .zip(&fitted)
                    .filter(|(_, f)| **f)
                    .map(|(v, _)| *v)
                    .collect()
            };
            let m = median(&mut pick(&melanin));
            let h = median(&mut pick(&hemoglobin));
            if count == 0 { (0.0, 0.01) } else { (m, h) }
        };
        for k in (0..n).filter(|&k| !fitted[k]) {
            melanin[k] = fill_m;
            hemoglobin[k] = fill_h;
        }
        let quantile = |v: &mut Vec<f32>, q: f64| -> f64 {
            if v.is_empty() {
                return 0.0;
            }
            let i = ((q * (v.len() - 1) as f64).round() as usize).min(v.len() - 1);
            f64::from(*v.select_nth_unstable_by(i, f32::total_cmp).1)
        };
        let summary = MapsSummary {
            fitted: count,
            in_gamut: in_gamut.iter().filter(|g| **g).count(),
            invalid,
            median_de: quantile(&mut residuals, 0.5),
            p95_de: quantile(&mut residuals, 0.95),
            max_de: residuals.iter().copied().fold(0.0f32, f32::max).into(),
            eumelanin_spread: shared.beta_spread,
            exposure: gain,
            exposure_spread: shared.gain_spread,
            regions: regions.as_ref().map(|r| r.summary),
            thin_epidermis: thin
                .as_ref()
                .map_or(0, |t| t.texels.iter().filter(|f| **f).count()),
        };
        let eumelanin_map = regions.as_ref().map(|r| {
            r.label_of_texel
                .iter()
                .map(|&l| r.betas[usize::from(l)] as f32)
                .collect()
        });
        Ok(Maps {
            melanin,
            hemoglobin,
            eumelanin: regions.as_ref().map_or(beta, |r| r.summary.median),
            eumelanin_map,
            delta_e,
            in_gamut,
            fitted,
            thin_epidermis: thin,
            summary,
        })
    }

    /// β_m and the exposure, each given or fitted over a sample of the fitted texels, with the
    /// ranges the sample allows (module doc). Both fitted: alternately, the gain at β_m 0.6 (the
    /// medium preset's, the prior of `skin fit`), β_m at that gain, the gain again, β_m again.
    /// β_m 0.6 and gain 1 when nothing is fitted.
    fn fit_shared(&self, texels: &[[f32; 3]], fitted: &[bool], opts: &MapsOptions) -> Shared {
        let mut out = Shared {
            beta: match opts.eumelanin {
                Eumelanin::Fixed(b) => b,
                Eumelanin::Fit | Eumelanin::PerRegion(_) => 0.6,
            },
            gain: match opts.exposure {
                Exposure::Fixed(g) => g,
                Exposure::Auto | Exposure::WhiteBalance => [1.0; 3],
            },
            beta_spread: None,
            gain_spread: None,
        };
        let fit_gain = !matches!(opts.exposure, Exposure::Fixed(_));
        // With regions, one β_m for the texture serves only the exposure fit.
        let fit_beta = match opts.eumelanin {
            Eumelanin::Fit => true,
            Eumelanin::PerRegion(_) => fit_gain,
            Eumelanin::Fixed(_) => false,
        };
        if !(fit_beta || fit_gain) {
            return out;
        }
        let sample = extended::sample_texels(texels, fitted, opts.beta_samples);
        if sample.is_empty() {
            return out;
        }
        let rms_of = |inv: &Inverter, gain: [f64; 3]| sample_rms(inv, &sample, gain);
        let steps = opts.beta_steps;
        let betas: Vec<f64> = (0..steps).map(|i| i as f64 / (steps - 1) as f64).collect();
        let [lo, hi] = EXPOSURE_RANGE.map(f64::log2);
        let stops: Vec<f64> = (0..EXPOSURE_STEPS)
            .map(|i| lo + (hi - lo) * i as f64 / (EXPOSURE_STEPS - 1) as f64)
            .collect();
        let tolerance = opts.beta_tolerance_de;
        let rounds = if fit_beta && fit_gain { 2 } else { 1 };
        for _ in 0..rounds {
            if fit_gain {
                let inv = Inverter::new(self.table.slice(out.beta));
                let rms: Vec<f64> = stops.iter().map(|s| rms_of(&inv, [s.exp2(); 3])).collect();
                let (stop, range) = best_on_grid(&stops, &rms, tolerance);
                out.gain = [stop.exp2(); 3];
                out.gain_spread = Some(FittedRange {
                    min: range.min.exp2(),
                    max: range.max.exp2(),
                    ..range
                });
                if opts.exposure == Exposure::WhiteBalance {
                    // Per channel, from the common gain: Nelder–Mead in log₂ g over the range.
                    let unit = |x: &[f64; 3]| x.map(|x| (lo + (hi - lo) * x).exp2());
                    let start = [(stop - lo) / (hi - lo); 3];
                    let budget = crate::nelder_mead::Budget {
                        x_tol: 1e-3,
                        f_tol: 1e-4,
                        max_evals: 150,
                    };
                    let best = crate::nelder_mead::minimize(
                        &mut |x: &[f64; 3]| rms_of(&inv, unit(x)),
                        start,
                        0.1,
                        budget,
                    );
                    out.gain = unit(&best.x);
                    out.gain_spread = None;
                }
            }
            if fit_beta {
                let rms: Vec<f64> = betas
                    .par_iter()
                    .map(|&b| rms_of(&Inverter::new(self.table.slice(b)), out.gain))
                    .collect();
                let (beta, range) = best_on_grid(&betas, &rms, tolerance);
                out.beta = beta;
                out.beta_spread = Some(range);
            }
        }
        out
    }

    /// The linear Rec.709 diffuse albedo of the skins C_m = `melanin`, C_h = `hemoglobin`
    /// (per texel) and β_m = `eumelanin`, on the table's interpolant.
    pub fn albedo(
        &self,
        melanin: &[f32],
        eumelanin: f64,
        hemoglobin: &[f32],
    ) -> Result<Vec<[f32; 3]>, MapsError> {
        if hemoglobin.len() != melanin.len() {
            return Err(MapsError::Length {
                what: "hemoglobin map",
                found: hemoglobin.len(),
                expected: melanin.len(),
            });
        }
        if !(0.0..=1.0).contains(&eumelanin) {
            return Err(MapsError::Option {
                name: "eumelanin",
                value: eumelanin,
                range: "[0, 1]",
            });
        }
        let slice = self.table.slice(eumelanin);
        Ok(melanin
            .par_iter()
            .zip(hemoglobin.par_iter())
            .with_min_len(CHUNK)
            .map(|(&m, &h)| {
                let lab = slice.lab(
                    u_of_melanin(f64::from(m)),
                    slice.v_of_hemoglobin(f64::from(h)),
                );
                lab_of(lab).to_xyz().to_linear_srgb().0.map(|c| c as f32)
            })
            .collect())
    }
}

impl MapsModel {
    /// The albedo of `maps` as [`MapsModel::albedo`], with β_m per texel where the maps have it
    /// (each distinct β_m value gets its slice) and the thin-epidermis skin's where a texel has
    /// it.
    pub fn albedo_of(&self, maps: &Maps) -> Result<Vec<[f32; 3]>, MapsError> {
        let mut out = self.albedo_per_beta(maps)?;
        if let Some(thin) = &maps.thin_epidermis {
            let n = maps.melanin.len();
            if thin.texels.len() != n {
                return Err(MapsError::Length {
                    what: "thin-epidermis flags",
                    found: thin.texels.len(),
                    expected: n,
                });
            }
            let pick: Vec<usize> = (0..n).filter(|&k| thin.texels[k]).collect();
            let sub = Maps {
                melanin: pick.iter().map(|&k| maps.melanin[k]).collect(),
                hemoglobin: pick.iter().map(|&k| maps.hemoglobin[k]).collect(),
                eumelanin: maps.eumelanin,
                eumelanin_map: maps
                    .eumelanin_map
                    .as_ref()
                    .map(|b| pick.iter().map(|&k| b[k]).collect()),
                delta_e: Vec::new(),
                in_gamut: Vec::new(),
                fitted: Vec::new(),
                thin_epidermis: None,
                summary: maps.summary.clone(),
            };
            let thin_model = MapsModel::from_table(thin.table.clone());
            for (k, a) in pick.iter().zip(thin_model.albedo_per_beta(&sub)?) {
                out[*k] = a;
            }
        }
        Ok(out)
    }

    /// [`MapsModel::albedo_of`] on this model's table alone.
    fn albedo_per_beta(&self, maps: &Maps) -> Result<Vec<[f32; 3]>, MapsError> {
        let Some(betas) = &maps.eumelanin_map else {
            return self.albedo(&maps.melanin, maps.eumelanin, &maps.hemoglobin);
        };
        let n = maps.melanin.len();
        if betas.len() != n || maps.hemoglobin.len() != n {
            return Err(MapsError::Length {
                what: "eumelanin or hemoglobin map",
                found: betas.len().min(maps.hemoglobin.len()),
                expected: n,
            });
        }
        let mut distinct: Vec<u32> = betas.iter().map(|b| b.to_bits()).collect();
        distinct.sort_unstable();
        distinct.dedup();
        let mut out = vec![[0.0f32; 3]; n];
        for bits in distinct {
            let beta = f64::from(f32::from_bits(bits));
            let pick: Vec<usize> = (0..n).filter(|&k| betas[k].to_bits() == bits).collect();
            let m: Vec<f32> = pick.iter().map(|&k| maps.melanin[k]).collect();
            let h: Vec<f32> = pick.iter().map(|&k| maps.hemoglobin[k]).collect();
            for (k, a) in pick.iter().zip(self.albedo(&m, beta.clamp(0.0, 1.0), &h)?) {
                out[*k] = a;
            }
        }
        Ok(out)
    }
}

/// Fit maps to `texels` in one call: [`MapsModel::load`] then [`MapsModel::fit`].
pub fn fit_maps(
    texels: &[[f32; 3]],
    mask: Option<&[bool]>,
    opts: &MapsOptions,
    progress: &(dyn Fn(usize) + Sync),
) -> Result<Maps, MapsError> {
    MapsModel::load(opts)?.fit(texels, mask, opts, progress)
}

/// RMS over `sample` of the ΔE2000 (capped at [`BETA_CAP_DE`]) between each texel and its
/// inversion by `inv` at the exposure `gain`, seen at the texture's own exposure.
fn sample_rms(inv: &Inverter, sample: &[[f32; 3]], gain: [f64; 3]) -> f64 {
    let g = gain.map(|g| g as f32);
    let sum: f64 = sample
        .par_iter()
        .with_min_len(256)
        .map(|t| {
            let r = inv.invert(&texel_lab(scaled(*t, g)).0);
            let seen = texel_lab(*t).0;
            let fit = if gain == [1.0; 3] {
                r.lab
            } else {
                unscaled(&r.lab, gain)
            };
            delta_e_2000_fast(&seen, &fit).min(BETA_CAP_DE).powi(2)
        })
        .sum();
    (sum / sample.len().max(1) as f64).sqrt()
}

/// A texel with its channels scaled by `gain`.
#[inline]
fn scaled(t: [f32; 3], gain: [f32; 3]) -> [f32; 3] {
    [t[0] * gain[0], t[1] * gain[1], t[2] * gain[2]]
}

/// β_m and the exposure of a texture, with the ranges the texels allow when fitted.
struct Shared {
    beta: f64,
    gain: [f64; 3],
    beta_spread: Option<FittedRange>,
    gain_spread: Option<FittedRange>,
}

/// The best of candidates `xs` (evenly spaced) by their RMS capped ΔE2000 `rms`, placed between
/// candidates by a parabola through the best and its neighbours, and the range around it where
/// the RMS (linear between candidates) stays within `tolerance_de` of the best candidate's.
fn best_on_grid(xs: &[f64], rms: &[f64], tolerance_de: f64) -> (f64, FittedRange) {
    let n = xs.len();
    let best = (0..n)
        .min_by(|&a, &b| rms[a].total_cmp(&rms[b]))
        .unwrap_or(0);
    let x = if best > 0 && best + 1 < n {
        let (a, b, c) = (rms[best - 1], rms[best], rms[best + 1]);
        let curvature = a - 2.0 * b + c;
        let shift = if curvature > 0.0 {
            (0.5 * (a - c) / curvature).clamp(-0.5, 0.5)
        } else {
            0.0
        };
        xs[best] + shift * (xs[1] - xs[0])
    } else {
        xs[best]
    };
    let limit = rms[best] + tolerance_de;
    let mut lo = best;
    while lo > 0 && rms[lo - 1] <= limit {
        lo -= 1;
    }
    let mut hi = best;
    while hi + 1 < n && rms[hi + 1] <= limit {
        hi += 1;
    }
    // Each end where the RMS, linear between candidates, crosses the limit.
    let crossing = |inside: usize, outside: usize| -> f64 {
        let (a, b) = (rms[inside], rms[outside]);
        let t = if b > a {
            ((limit - a) / (b - a)).clamp(0.0, 1.0)
        } else {
            0.0
        };
        xs[inside] + t * (xs[outside] - xs[inside])
    };
    let min = if lo > 0 { crossing(lo, lo - 1) } else { xs[lo] };
    let max = if hi + 1 < n {
        crossing(hi, hi + 1)
    } else {
        xs[hi]
    };
    (
        x,
        FittedRange {
            min: min.min(x),
            max: max.max(x),
            tolerance_de,
            best_rms_de: rms[best],
        },
    )
}
