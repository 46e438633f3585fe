//! A second skin per texel where the texture's skin cannot reach it: the same C_m, β_m, C_h
//! under a thin epidermis, as on the lip vermilion (docs/physics.md §18, "Thin epidermis").

use super::invert::Inverter;
use super::table::{ForwardTable, cache_key, melanin_of_u};
use super::{
    CHUNK, IN_GAMUT_DE, LOOKUP_NODES, Lookup, MEMO_SLOTS, MapsError, MapsOptions,
    delta_e_2000_fast, memo_slot, scaled, texel_lab, unscaled,
};
use crate::Parameter;
use rayon::prelude::*;
use std::sync::{Arc, Mutex};

/// Default epidermis thickness of the second skin, mm: the thin end of the viable epidermis
/// (0.05–0.1 mm, [SM03]), within the range of `skin fit`'s epidermis thickness.
pub const THIN_EPIDERMIS_MM: f64 = 0.05;

/// The default C_h range of the second skin's table (its top is the knob
/// [`super::MapsOptions::thin_hemoglobin_max`]): the plausible range of Aliaga et al.'s biophysical
/// skin model ([ALI23], hemoglobin fraction 0.001–0.25), which fits whole faces including the
/// lips, wider than [DJ06]'s 0.1 because the vermilion's capillaries lie dense under its thin
/// epithelium (docs/physics.md §18, "Thin epidermis").
pub const THIN_HEMOGLOBIN_RANGE: [f64; 2] = [0.001, 0.25];

/// ΔE2000 by which the thin-epidermis skin must reproduce a texel better to replace the
/// texture's skin there: one just-noticeable difference, so that texels the texture's skin
/// nearly reaches keep it.
pub const THIN_MIN_GAIN_DE: f64 = 1.0;

/// The texels fitted under the thin epidermis and the table they were fitted on.
#[derive(Debug, Clone, PartialEq)]
pub struct ThinEpidermis {
    /// Epidermis thickness of the second skin, mm.
    pub epidermis_mm: f64,
    /// Per texel: fitted under the thin epidermis.
    pub texels: Vec<bool>,
    /// The forward table of the thin-epidermis skin.
    pub table: ForwardTable,
}

/// Thin-epidermis tables loaded by a model, by cache key: each is built or read once.
pub(super) type Tables = Arc<Mutex<Vec<(String, ForwardTable)>>>;

/// A memo slot: the texel's bits, its label and its refit (C_m, C_h, ΔE2000).
type MemoEntry = Option<([u32; 3], usize, (f32, f32, f32))>;

/// One texel's refit: index, C_m, C_h, ΔE2000.
type Refit = (usize, f32, f32, f32);

/// The thin-epidermis table of `opts`: from `tables`, else the disk cache as the main table.
fn load_table(
    tables: &Tables,
    opts: &MapsOptions,
    epidermis_mm: f64,
) -> Result<ForwardTable, MapsError> {
    let base = Parameter::EpidermisThickness
        .set(opts.base, epidermis_mm)
        .map_err(crate::FitError::from)?;
    let range = [THIN_HEMOGLOBIN_RANGE[0], opts.thin_hemoglobin_max];
    let key = cache_key(opts.table, &base, range);
    let mut held = tables
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    if let Some((_, t)) = held.iter().find(|(k, _)| *k == key) {
        return Ok(t.clone());
    }
    let build = || ForwardTable::build_over(opts.table, base, range);
    let (table, _) = skin_io::cache::load_or_build(
        opts.cache_dir.as_deref(),
        opts.cache_max_bytes,
        &key,
        build,
    )?;
    let table =
        if table.is_whole() && table.size() == opts.table && table.hemoglobin_range() == range {
            table
        } else {
            build()?
        };
    held.push((key, table.clone()));
    Ok(table)
}

/// Refit the texels `candidates` (fitted, out of gamut, valid) under the thin epidermis: the
/// texel with label `l` (its β_m, `betas[l]`) on the thin table's slice at that β_m, through
/// the gains `gain`. Returns the refits that beat `delta_e` by [`THIN_MIN_GAIN_DE`].
#[allow(clippy::too_many_arguments)]
pub(super) fn refit(
    tables: &Tables,
    opts: &MapsOptions,
    epidermis_mm: f64,
    texels: &[[f32; 3]],
    candidates: &[usize],
    labels: Option<&[u8]>,
    betas: &[f64],
    gain: [f64; 3],
    delta_e: &[f32],
) -> Result<(ForwardTable, Vec<Refit>), MapsError> {
    let table = load_table(tables, opts, epidermis_mm)?;
    let label_of = |k: usize| labels.map_or(0, |l| usize::from(l[k]));
    let mut uses = vec![0usize; betas.len()];
    for &k in candidates {
        uses[label_of(k)] += 1;
    }
    let inverters: Vec<Option<Inverter>> = betas
        .par_iter()
        .zip(&uses)
        .map(|(&b, &u)| {
            let with_lookup = match opts.lookup {
                Lookup::Always => true,
                Lookup::Auto => u > LOOKUP_NODES,
                Lookup::Never => false,
            };
            (u > 0).then(|| {
                if with_lookup {
                    Inverter::with_lookup(table.slice(b))
                } else {
                    Inverter::new(table.slice(b))
                }
            })
        })
        .collect();
    let gain32 = gain.map(|g| g as f32);
    let unit_gain = gain == [1.0; 3];
    let refits = candidates
        .par_chunks(CHUNK)
        .flat_map_iter(|chunk| {
            let mut memo: Vec<MemoEntry> = vec![None; MEMO_SLOTS];
            let mut out = Vec::new();
            for &k in chunk {
                let label = label_of(k);
                let Some(inv) = &inverters[label] else {
                    continue;
                };
                let bits = texels[k].map(f32::to_bits);
                let slot = memo_slot(bits);
                let (m, h, de) = match memo[slot] {
                    Some((b, l, r)) if b == bits && l == label => r,
                    _ => {
                        let (lab, _) = texel_lab(scaled(texels[k], gain32));
                        let r = inv.invert_fast(&lab);
                        let (seen, fit) = if unit_gain {
                            (lab, r.lab)
                        } else {
                            (texel_lab(texels[k]).0, unscaled(&r.lab, gain))
                        };
                        let out = (
                            melanin_of_u(r.u) as f32,
                            inv.slice().hemoglobin_of_v(r.v) as f32,
                            delta_e_2000_fast(&seen, &fit) as f32,
                        );
                        memo[slot] = Some((bits, label, out));
                        out
                    }
                };
                if f64::from(de) + THIN_MIN_GAIN_DE <= f64::from(delta_e[k]) {
                    out.push((k, m, h, de));
                }
            }
            out
        })
        .collect();
    Ok((table, refits))
}

/// Whether a refit ΔE2000 is in gamut.
#[must_use]
pub(super) fn in_gamut(de: f32) -> bool {
    f64::from(de) <= IN_GAMUT_DE
}
