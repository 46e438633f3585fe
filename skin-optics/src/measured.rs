//! Measured skin presets: skins fitted to the median spectra of the International Skin Spectra
//! Archive per group and body site ([ISSA25]; docs/physics.md §13), plus one per ITA° category.
//!
//! The table `data/measured_presets.csv` is written by `skin-validate presets` (SCI geometry,
//! `--model auto`, exact forward model) from `data/skin_reflectance_issa_summary.csv`; a preset's
//! colour is its fitted skin's diffuse (SCE) reflectance under D65.

use crate::lab::{ItaCategory, Lab};
use crate::params::{Preset, SkinParams};
use crate::physiology::{Extension, Physiology};
use std::sync::OnceLock;

/// One measured preset.
#[derive(Debug, Clone, PartialEq)]
pub struct MeasuredPreset {
    /// Name, `<group code>-<site>` in lower case, e.g. `ca-forehead`.
    pub name: String,
    /// ISSA group code (CA Caucasian, CN Chinese, JP Japanese, TH Thai, SA South Asian,
    /// IQ Iraqi, AB Arabian, AF African).
    pub group_code: String,
    /// Body site (forehead, cheek, inner_arm).
    pub site: String,
    /// Records behind the median.
    pub n_records: u32,
    /// The fitted skin.
    pub skin: SkinParams,
    /// RMS reflectance residual of the fit to the median.
    pub rms: f64,
    /// CIELAB colour of the fitted skin (diffuse, D65).
    pub lab: Lab,
}

/// Every group/site preset, in table order.
#[must_use]
pub fn measured_presets() -> &'static [MeasuredPreset] {
    static TABLE: OnceLock<Vec<MeasuredPreset>> = OnceLock::new();
    TABLE.get_or_init(|| parse(include_str!("../data/measured_presets.csv")))
}

/// The ITA° category presets: for each category that some group/site preset falls in, the preset
/// with the median ITA° among them, named `ita-<category>` (spaces as dashes), e.g. `ita-tan`.
#[must_use]
pub fn ita_presets() -> Vec<(String, &'static MeasuredPreset)> {
    let mut out = Vec::new();
    for cat in ItaCategory::ALL {
        let mut members: Vec<&MeasuredPreset> = measured_presets()
            .iter()
            .filter(|p| p.lab.ita_category() == cat)
            .collect();
        if members.is_empty() {
            continue;
        }
        members.sort_by(|a, b| a.lab.ita_deg().total_cmp(&b.lab.ita_deg()));
        let name = format!("ita-{}", cat.name().replace(' ', "-"));
        out.push((name, members[members.len() / 2]));
    }
    out
}

/// The measured preset called `name` (case-insensitive): a group/site name or an `ita-` name.
#[must_use]
pub fn find_measured(name: &str) -> Option<&'static MeasuredPreset> {
    let n = name.trim().to_ascii_lowercase();
    measured_presets().iter().find(|p| p.name == n).or_else(|| {
        ita_presets()
            .into_iter()
            .find(|(k, _)| *k == n)
            .map(|(_, p)| p)
    })
}

/// Error for a skin name that is neither a seed preset nor a measured one (the name as given, cut
/// by [`crate::echo::text`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "unknown skin preset '{0}' (valid: light or paper, medium, dark, or a measured preset such as ca-forehead or ita-tan; `skin presets` lists them)"
)]
pub struct UnknownSkin(pub String);

/// The skin called `name` (case-insensitive): a seed [`Preset`] (`light` = `paper`, `medium`,
/// `dark`) or a measured preset ([`find_measured`]). The one resolver of skin names, for the
/// command line and scene files alike.
pub fn named_skin(name: &str) -> Result<SkinParams, UnknownSkin> {
    match name.parse::<Preset>() {
        Ok(p) => Ok(SkinParams::preset(p)),
        Err(_) => find_measured(name)
            .map(|m| m.skin)
            .ok_or_else(|| UnknownSkin(crate::echo::text(name))),
    }
}

/// Parse the embedded table; a malformed row is a build-time defect the unit tests catch, so it
/// panics with the row.
fn parse(text: &str) -> Vec<MeasuredPreset> {
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .skip(1)
        .map(|line| {
            let f: Vec<&str> = line.split(',').collect();
            let num = |i: usize| -> f64 {
                f[i].parse()
                    .unwrap_or_else(|_| panic!("measured presets: field {i} of '{line}'"))
            };
            let physiology = Physiology::SEED
                .with(Extension::EpidermisBlood, num(11))
                .and_then(|x| x.with(Extension::Bilirubin, num(12)))
                .and_then(|x| x.with(Extension::MieScale, num(13)))
                .and_then(|x| x.with(Extension::RayleighScale, num(14)))
                .unwrap_or_else(|e| panic!("measured presets: {e} in '{line}'"));
            let skin = SkinParams::new(num(4), num(5), num(6), num(7))
                .and_then(|s| s.with_oxygenation(num(8)))
                .and_then(|s| s.with_epidermis_thickness_mm(num(9)))
                .and_then(|s| s.with_dermis_scattering_scale(num(10)))
                .unwrap_or_else(|e| panic!("measured presets: {e} in '{line}'"))
                .with_physiology(physiology);
            MeasuredPreset {
                name: f[0].to_string(),
                group_code: f[1].to_string(),
                site: f[2].to_string(),
                n_records: num(3) as u32,
                skin,
                rms: num(15),
                lab: Lab {
                    l: num(16),
                    a: num(17),
                    b: num(18),
                },
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_holds_every_group_and_site_with_physiological_values() {
        let all = measured_presets();
        assert_eq!(all.len(), 24);
        for p in all {
            assert!(p.rms < 0.02, "{}: rms {}", p.name, p.rms);
            assert!(
                p.skin.melanin() <= 0.5 && p.skin.hemoglobin() <= 0.1,
                "{}",
                p.name
            );
            assert!(p.skin.epidermis_thickness_mm() >= 0.04, "{}", p.name);
            assert!(p.n_records > 0);
        }
        assert_eq!(find_measured("CA-Forehead").unwrap().name, "ca-forehead");
        assert!(find_measured("xx-elbow").is_none());
    }

    /// The measured colours span what people look like (the archive's medians: L* roughly 34–67),
    /// unlike the paper's Figure 1 skin (L* 75, b* 7): every preset is darker and yellower than it.
    #[test]
    fn measured_colours_look_like_people() {
        for p in measured_presets() {
            assert!((30.0..70.0).contains(&p.lab.l), "{}: {:?}", p.name, p.lab);
            assert!(p.lab.b > 12.0, "{}: {:?}", p.name, p.lab);
        }
    }

    #[test]
    fn named_skin_resolves_seed_and_measured_names() {
        assert_eq!(
            named_skin("Paper").unwrap(),
            SkinParams::preset(Preset::Light)
        );
        assert_eq!(
            named_skin("ita-dark").unwrap(),
            find_measured("ita-dark").unwrap().skin
        );
        // A measured preset keeps its extended physiology.
        let p = named_skin("ca-inner-arm").unwrap();
        assert_eq!(
            p.physiology(),
            find_measured("ca-inner-arm").unwrap().skin.physiology()
        );
        let e = named_skin("tan").unwrap_err().to_string();
        assert!(e.contains("'tan'") && e.contains("skin presets"), "{e}");
    }

    #[test]
    fn ita_presets_fall_in_their_category() {
        let ita = ita_presets();
        assert!(ita.len() >= 4, "{}", ita.len());
        for (name, p) in &ita {
            let cat = p.lab.ita_category().name().replace(' ', "-");
            assert_eq!(*name, format!("ita-{cat}"));
            assert_eq!(find_measured(name), Some(*p));
        }
    }
}
