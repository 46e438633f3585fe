//! A skin slab's exact totals over its thickness, as the image's luminance sees them (docs/physics.md
//! §16.6): R(d) and T(d) of `multipole::skin::thin_slab` (adding-doubling, normal incidence) every
//! 10 nm over 380–780 nm, weighted by ȳ(λ) D65(λ), on a uniform grid of thicknesses. Between nodes
//! R is linear and ln T is linear in d (T falls nearly exponentially, e^(−d/δ) with δ the
//! dermis' diffusion length), so the grid step is set by the measured interpolation error
//! ([`STEP_MM`]). The table is what the thin-part criterion (`super::thin`) reads at each probe.

use crate::media::SkinMedia;
use multipole::MultipoleError;
use multipole::exact::adding_doubling::{self, AddingDoublingOptions};
use multipole::skin::thin_slab;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use skin_io::cache;
use std::path::Path;

/// Thickness step of the table, mm. Against adding-doubling at 24 points at every half step from
/// 0.25 mm to the table's end, the largest errors, at the midpoints of the first millimetre (where the luminance
/// mixes exponentials of very different lengths), are 0.7 / 2.4 / 7.9% of T and 1.7 / 1.2 / 2.2%
/// of R∞ (light / medium / dark skin; 0.2% of T at the nodes, the 12-point quadrature). At the
/// criterion's 5% share an error x in T moves the thickness where a part turns thin by x δ (δ
/// the transmission's decay length): under 0.1 δ. Half this step costs twice the build (about
/// 0.1 s a material) for a quarter of the interpolation error
/// (`the_table_interpolates_adding_doubling_within_its_stated_error`).
pub const STEP_MM: f64 = 0.25;

/// Adding-doubling quadrature points of the table (fewer than the totals' 24: a criterion's
/// threshold needs percent, not 10⁻⁴; the error is in the interpolation test's bound).
const QUADRATURE_POINTS: usize = 12;

/// Version of what [`SlabTable::build`] computes from its inputs: bump it whenever the same media
/// would give another table (the weighting, the grid, the solver's options).
const SLAB_TABLE_VERSION: u32 = 1;

/// The luminance of a skin slab's diffuse reflectance and transmittance over its thickness.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SlabTable {
    /// R(d_i) at d_i = i · STEP_MM, i = 0..n (R(0) = 0).
    reflectance: Vec<f32>,
    /// ln T(d_i) (ln T(0) = 0: nothing is in the way).
    ln_transmittance: Vec<f32>,
    /// The half-space's R∞.
    half_space: f32,
}

impl SlabTable {
    /// [`SlabTable::build`] through the disk cache in `dir` (`None`: built in memory), keyed by
    /// every layered medium it reads (coefficients, thicknesses, indices and surface, every 10
    /// nm), g, the table's constants, `t_floor` and `max_mm`.
    pub fn cached(
        media: &SkinMedia,
        t_floor: f64,
        max_mm: f64,
        dir: Option<&Path>,
    ) -> Result<Self, MultipoleError> {
        let rows: Vec<(f64, &multipole::LayeredMedium)> = media.every_10nm().collect();
        let key = format!(
            "slab-table v{SLAB_TABLE_VERSION} step {STEP_MM:?} points {QUADRATURE_POINTS} g {:?} \
             floor {t_floor:?} max {max_mm:?} rows {rows:?}",
            media.phase_g
        );
        let max_bytes = cache::max_bytes().unwrap_or(cache::DEFAULT_MAX_BYTES);
        cache::load_or_build(dir, max_bytes, &key, || Self::build(media, t_floor, max_mm))
            .map(|(table, _)| table)
    }

    /// The table of `media` from 0 to the first node where T falls below `t_floor` · R∞ (at most
    /// `max_mm`), from adding-doubling at every 10 nm (in parallel over wavelengths).
    pub fn build(media: &SkinMedia, t_floor: f64, max_mm: f64) -> Result<Self, MultipoleError> {
        let options = AddingDoublingOptions::new(QUADRATURE_POINTS, media.phase_g)
            .map_err(MultipoleError::from)?;
        let rows: Vec<(f64, &multipole::LayeredMedium)> = media.every_10nm().collect();
        let weight = |nm: f64| skin_optics::color::cie_xyz_bar(nm)[1] * skin_optics::color::d65(nm);
        let w_sum: f64 = rows.iter().map(|&(nm, _)| weight(nm)).sum();
        let luminance = |f: &(
                              dyn Fn(&multipole::LayeredMedium) -> Result<f64, MultipoleError>
                                  + Sync
                          )|
         -> Result<f64, MultipoleError> {
            let parts: Result<Vec<f64>, MultipoleError> = rows
                .par_iter()
                .map(|&(nm, m)| Ok(weight(nm) * f(m)?))
                .collect();
            Ok(parts?.iter().sum::<f64>() / w_sum)
        };
        let half_space =
            luminance(&|m| Ok(adding_doubling::solve(m, &options)?.diffuse_reflectance))?;
        let mut reflectance = vec![0.0f32];
        let mut ln_transmittance = vec![0.0f32];
        let n_max = (max_mm / STEP_MM).ceil() as usize;
        for i in 1..=n_max {
            let d = i as f64 * STEP_MM;
            let totals = rows
                .par_iter()
                .map(|&(nm, m)| {
                    let t = thin_slab::slab_totals(m, d, &options)?;
                    Ok((
                        weight(nm) * t.diffuse_reflectance,
                        weight(nm) * t.transmittance,
                    ))
                })
                .collect::<Result<Vec<(f64, f64)>, MultipoleError>>()?;
            let (r, t) = totals
                .iter()
                .fold((0.0, 0.0), |(a, b), &(r, t)| (a + r, b + t));
            let (r, t) = (r / w_sum, (t / w_sum).max(f64::MIN_POSITIVE));
            reflectance.push(r as f32);
            ln_transmittance.push(t.ln() as f32);
            if t < t_floor * half_space {
                break;
            }
        }
        Ok(Self {
            reflectance,
            ln_transmittance,
            half_space: half_space as f32,
        })
    }

    /// The half-space's diffuse reflectance R∞ (luminance, per incident photon).
    #[must_use]
    pub fn half_space_reflectance(&self) -> f32 {
        self.half_space
    }

    /// The thickest slab tabulated, mm: T there is below the floor the table was built to.
    #[must_use]
    pub fn max_mm(&self) -> f32 {
        ((self.reflectance.len() - 1) as f64 * STEP_MM) as f32
    }

    /// (R(d), T(d)) of a slab `d_mm` thick (luminance, per incident photon); beyond the table,
    /// the half-space (R∞, 0).
    #[must_use]
    pub fn totals(&self, d_mm: f32) -> (f32, f32) {
        let x = d_mm.max(0.0) / STEP_MM as f32;
        let last = self.reflectance.len() - 1;
        if x.is_nan() || x >= last as f32 {
            return (self.half_space, 0.0);
        }
        let i = x as usize;
        let f = x - i as f32;
        let lerp = |v: &[f32]| v[i] + f * (v[i + 1] - v[i]);
        (lerp(&self.reflectance), lerp(&self.ln_transmittance).exp())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use multipole::skin::thin_slab;
    use skin_optics::{Preset, SkinParams};

    fn media(preset: Preset) -> SkinMedia {
        SkinMedia::new(&SkinParams::preset(preset), multipole::DEFAULT_G).unwrap()
    }

    /// The luminance of adding-doubling's totals at `d_mm` computed directly (24 quadrature
    /// points, every 10 nm), the reference the table is checked against.
    fn direct(media: &SkinMedia, d_mm: f64) -> (f64, f64) {
        let options = AddingDoublingOptions::new(24, media.phase_g).unwrap();
        let (mut r, mut t, mut w) = (0.0, 0.0, 0.0);
        for (nm, m) in media.every_10nm() {
            let k = skin_optics::color::cie_xyz_bar(nm)[1] * skin_optics::color::d65(nm);
            let s = thin_slab::slab_totals(m, d_mm, &options).unwrap();
            r += k * s.diffuse_reflectance;
            t += k * s.transmittance;
            w += k;
        }
        (r / w, t / w)
    }

    /// Through the cache the table is the one built directly, to the bit; a second load reads
    /// the entry the first wrote (one file); another skin or another floor is another entry.
    #[test]
    fn the_cached_table_is_the_built_one_and_is_keyed_by_its_inputs() {
        let dir = tempfile::tempdir().unwrap();
        let files = || std::fs::read_dir(dir.path()).unwrap().count();
        let light = media(Preset::Light);
        let built = SlabTable::build(&light, 5e-5, 4.0).unwrap();
        let first = SlabTable::cached(&light, 5e-5, 4.0, Some(dir.path())).unwrap();
        assert_eq!(first, built);
        assert_eq!(files(), 1);
        let second = SlabTable::cached(&light, 5e-5, 4.0, Some(dir.path())).unwrap();
        assert_eq!(second, built);
        assert_eq!(files(), 1);
        let dark = SlabTable::cached(&media(Preset::Dark), 5e-5, 4.0, Some(dir.path())).unwrap();
        assert_ne!(dark, built);
        SlabTable::cached(&light, 1e-4, 4.0, Some(dir.path())).unwrap();
        assert_eq!(files(), 3);
    }

    /// Between nodes (at the midpoints, where linear interpolation errs most) and at nodes, the
    /// table's R and T are adding-doubling's at 24 points within 10% of T (plus 10⁻⁵ absolute)
    /// and 3% of R∞, two-sided, for light, medium and dark skin from 0.25 mm to the table's end
    /// (measured at most 7.9% and 2.2%, `STEP_MM`).
    #[test]
    fn the_table_interpolates_adding_doubling_within_its_stated_error() {
        for preset in [Preset::Light, Preset::Medium, Preset::Dark] {
            let m = media(preset);
            let table = SlabTable::build(&m, 5e-5, 60.0).unwrap();
            let r_inf = f64::from(table.half_space_reflectance());
            let mut d = STEP_MM;
            while d < f64::from(table.max_mm()) {
                let (r, t) = table.totals(d as f32);
                let (r_ad, t_ad) = direct(&m, d);
                assert!(
                    (f64::from(t) - t_ad).abs() <= 0.1 * t_ad + 1e-5,
                    "{preset:?} {d} mm: T {t} vs {t_ad}"
                );
                assert!(
                    (f64::from(r) - r_ad).abs() <= 0.03 * r_inf,
                    "{preset:?} {d} mm: R {r} vs {r_ad}"
                );
                d += 0.5 * STEP_MM;
            }
        }
    }

    /// The table ends where T < floor · R∞ and returns the half-space (R∞, 0) beyond; light skin
    /// transmits more than medium, which transmits more than dark, so its table is the longest.
    #[test]
    fn the_table_ends_at_its_transmission_floor() {
        let lengths: Vec<f32> = [Preset::Light, Preset::Medium, Preset::Dark]
            .into_iter()
            .map(|p| {
                let t = SlabTable::build(&media(p), 5e-5, 60.0).unwrap();
                let (r_end, t_end) = t.totals(t.max_mm());
                assert_eq!((r_end, t_end), (t.half_space_reflectance(), 0.0));
                let (_, t_last) = t.totals(t.max_mm() - 0.01);
                assert!(
                    t_last < 1.2 * 5e-5 * t.half_space_reflectance(),
                    "{p:?}: {t_last}"
                );
                let (_, t_before) = t.totals(t.max_mm() - STEP_MM as f32 - 0.01);
                assert!(
                    t_before >= 5e-5 * t.half_space_reflectance(),
                    "{p:?}: {t_before}"
                );
                t.max_mm()
            })
            .collect();
        assert!(
            lengths[0] > lengths[1] && lengths[1] > lengths[2],
            "{lengths:?}"
        );
    }
}
