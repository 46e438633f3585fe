//! Every named skin with its colour: the seed model's presets, the measured (ISSA) presets and the
//! ITA° category presets, as `skin presets` and the Python package list them.

use crate::{ColourModel, FitError};
use multipole::Method;
use skin_optics::lab::Lab;
use skin_optics::measured::{ita_presets, measured_presets};
use skin_optics::{Preset, SkinParams};

/// A named skin: its name, where it comes from, its parameters and its colour.
#[derive(Debug, Clone, PartialEq)]
pub struct NamedSkin {
    /// The preset's name (`paper`, `medium`, `ca-forehead`, ...).
    pub name: String,
    /// Its source, in words.
    pub source: String,
    /// Its parameters.
    pub skin: SkinParams,
    /// Its diffuse (SCE) colour under D65, CIELAB (exact model, 10-nm step for the seed presets;
    /// the stored fit's colour for the measured ones).
    pub lab: Lab,
}

/// Every named skin: the seed presets first, then the measured ones, then the ITA° categories.
pub fn named_skins() -> Result<Vec<NamedSkin>, FitError> {
    let colour = ColourModel::new(10.0, Method::Exact, SkinParams::default())?;
    let mut rows = Vec::new();
    for (name, p) in [
        ("paper", Preset::Light),
        ("medium", Preset::Medium),
        ("dark", Preset::Dark),
    ] {
        let skin = SkinParams::preset(p);
        let source = if p == Preset::Light {
            "the paper's Figure 1 (also `light`)"
        } else {
            "seed model, this project's values"
        };
        rows.push(NamedSkin {
            name: name.to_string(),
            source: source.to_string(),
            skin,
            lab: colour.lab(&skin)?,
        });
    }
    for p in measured_presets() {
        rows.push(NamedSkin {
            name: p.name.clone(),
            source: format!(
                "ISSA {} {} median of {} (fit RMS {:.4})",
                p.group_code, p.site, p.n_records, p.rms
            ),
            skin: p.skin,
            lab: p.lab,
        });
    }
    for (name, p) in ita_presets() {
        rows.push(NamedSkin {
            name,
            source: format!("= {}", p.name),
            skin: p.skin,
            lab: p.lab,
        });
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The seed presets' colours get darker from paper to dark (L* falls), and every name is unique.
    #[test]
    fn seed_presets_darken_and_names_are_unique() {
        let rows = named_skins().unwrap();
        let l: Vec<f64> = rows[..3].iter().map(|r| r.lab.l).collect();
        assert!(l[0] > l[1] && l[1] > l[2], "{l:?}");
        let mut names: Vec<&str> = rows.iter().map(|r| r.name.as_str()).collect();
        names.sort_unstable();
        let n = names.len();
        names.dedup();
        assert_eq!(names.len(), n);
    }
}
