//! Physical re-toning: operations on fitted maps (tanning, pallor, flush), after which the
//! albedo is the forward model of the edited maps.

use super::MapsError;
use crate::{EUMELANIN_RANGE, HEMOGLOBIN_RANGE, MELANIN_RANGE};
use std::fmt;
use std::str::FromStr;

/// One edit of the maps. Results are clamped to the model's ranges (C_m ∈ [0, 0.5],
/// C_h ∈ [0.001, 0.1], or the thin-epidermis skin's C_h range where a texel has that skin).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Edit {
    /// C_m ← C_m · s (`melanin*S`), s ≥ 0.
    MelaninScale(f64),
    /// C_m ← C_m + d (`melanin+D` or `melanin-D`).
    MelaninOffset(f64),
    /// C_h ← C_h · s (`hemoglobin*S`), s ≥ 0; under the hemoglobin weight map if one is given.
    HemoglobinScale(f64),
    /// C_h ← C_h + d (`hemoglobin+D` or `hemoglobin-D`); under the hemoglobin weight map if given.
    HemoglobinOffset(f64),
    /// β_m ← b for the whole texture (`eumelanin=B`), b ∈ [0, 1].
    Eumelanin(f64),
}

/// The edit syntax, for messages.
pub const EDIT_SYNTAX: &str =
    "melanin*S, melanin+D, melanin-D, hemoglobin*S, hemoglobin+D, hemoglobin-D or eumelanin=B";

impl FromStr for Edit {
    type Err = MapsError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let text = s.trim();
        let bad = || MapsError::Edit {
            text: skin_optics::echo::Text(text).to_string(),
        };
        let split = text.find(['*', '+', '-', '=']).ok_or_else(bad)?;
        let (name, rest) = text.split_at(split);
        let op = rest.as_bytes()[0];
        let value: f64 = rest[1..].trim().parse().map_err(|_| bad())?;
        if !value.is_finite() {
            return Err(bad());
        }
        let signed = if op == b'-' { -value } else { value };
        let edit = match (name.trim(), op) {
            ("melanin", b'*') => Edit::MelaninScale(value),
            ("melanin", b'+' | b'-') => Edit::MelaninOffset(signed),
            ("hemoglobin", b'*') => Edit::HemoglobinScale(value),
            ("hemoglobin", b'+' | b'-') => Edit::HemoglobinOffset(signed),
            ("eumelanin", b'=') => Edit::Eumelanin(value),
            _ => return Err(bad()),
        };
        edit.validate()?;
        Ok(edit)
    }
}

impl fmt::Display for Edit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Edit::MelaninScale(s) => write!(f, "melanin*{s}"),
            Edit::MelaninOffset(d) => write!(f, "melanin{d:+}"),
            Edit::HemoglobinScale(s) => write!(f, "hemoglobin*{s}"),
            Edit::HemoglobinOffset(d) => write!(f, "hemoglobin{d:+}"),
            Edit::Eumelanin(b) => write!(f, "eumelanin={b}"),
        }
    }
}

impl Edit {
    /// Check the edit's value against its range.
    pub fn validate(&self) -> Result<(), MapsError> {
        let (name, value, ok, range) = match *self {
            Edit::MelaninScale(s) => ("melanin scale", s, (0.0..=100.0).contains(&s), "[0, 100]"),
            Edit::MelaninOffset(d) => ("melanin offset", d, d.abs() <= 0.5, "[-0.5, 0.5]"),
            Edit::HemoglobinScale(s) => (
                "hemoglobin scale",
                s,
                (0.0..=100.0).contains(&s),
                "[0, 100]",
            ),
            Edit::HemoglobinOffset(d) => ("hemoglobin offset", d, d.abs() <= 0.1, "[-0.1, 0.1]"),
            Edit::Eumelanin(b) => (
                "eumelanin",
                b,
                (EUMELANIN_RANGE[0]..=EUMELANIN_RANGE[1]).contains(&b),
                "[0, 1]",
            ),
        };
        if ok && value.is_finite() {
            Ok(())
        } else {
            Err(MapsError::Option { name, value, range })
        }
    }
}

/// Apply `edits` in order to `maps`. `hemoglobin_weight` (one weight in [0, 1] per texel, e.g. a
/// blush mask) blends each hemoglobin edit with the unedited value; weights outside [0, 1] or
/// non-finite are clamped (NaN counts as 0).
pub fn apply(
    maps: &mut super::Maps,
    edits: &[Edit],
    hemoglobin_weight: Option<&[f32]>,
) -> Result<(), MapsError> {
    if let Some(w) = hemoglobin_weight
        && w.len() != maps.melanin.len()
    {
        return Err(MapsError::Length {
            what: "hemoglobin weight map",
            found: w.len(),
            expected: maps.melanin.len(),
        });
    }
    let weight = |k: usize| {
        hemoglobin_weight.map_or(1.0, |w| {
            let x = f64::from(w[k]);
            if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) }
        })
    };
    let [m_lo, m_hi] = MELANIN_RANGE;
    // A texel keeps the C_h range of the skin it was fitted under.
    let thin = maps
        .thin_epidermis
        .as_ref()
        .map(|t| (t.texels.clone(), t.table.hemoglobin_range()));
    let hemoglobin_range = |k: usize| match &thin {
        Some((texels, range)) if texels.get(k) == Some(&true) => *range,
        _ => HEMOGLOBIN_RANGE,
    };
    for e in edits {
        e.validate()?;
        match *e {
            Edit::MelaninScale(s) => {
                for c in &mut maps.melanin {
                    *c = (f64::from(*c) * s).clamp(m_lo, m_hi) as f32;
                }
            }
            Edit::MelaninOffset(d) => {
                for c in &mut maps.melanin {
                    *c = (f64::from(*c) + d).clamp(m_lo, m_hi) as f32;
                }
            }
            Edit::HemoglobinScale(_) | Edit::HemoglobinOffset(_) => {
                for (k, c) in maps.hemoglobin.iter_mut().enumerate() {
                    let old = f64::from(*c);
                    let new = match *e {
                        Edit::HemoglobinScale(s) => old * s,
                        Edit::HemoglobinOffset(d) => old + d,
                        _ => old,
                    }
                    .clamp(hemoglobin_range(k)[0], hemoglobin_range(k)[1]);
                    *c = (old + weight(k) * (new - old)) as f32;
                }
            }
            Edit::Eumelanin(b) => {
                maps.eumelanin = b;
                if let Some(map) = &mut maps.eumelanin_map {
                    map.fill(b as f32);
                }
            }
        }
    }
    Ok(())
}
