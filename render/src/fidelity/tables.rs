//! A skin's BSSRDF tables with every fidelity choice applied, through the disk cache, and the
//! record of what was chosen ([`SkinChoices`]).

use super::explain::{SkinChoices, TransportChoice, diffusion_failures};
use super::key::table_key;
use super::photons::{self, PhotonChoice};
use super::wavelengths::{self, WavelengthChoice};
use super::{FidelityKnobs, Lod, PhotonPolicy, Resolved, StepChoice};
use crate::bssrdf::{ProfileTable, TableOptions};
use crate::media::SkinMedia;
use multipole::skin::{ExactShape, ShapeTableOptions};
use multipole::{Method, MultipoleError};
use serde::{Deserialize, Serialize};
use skin_io::cache;
use skin_optics::SkinParams;
use std::path::PathBuf;
use std::time::Instant;

/// What a cache entry holds: the table and the wavelength choice that sized it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct Stored {
    table: ProfileTable,
    wavelengths: WavelengthChoice,
}

/// Where the shapes' photons come from: run-time escapes, or the universal table's photons
/// (`None`: the default table).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Shapes {
    Escapes(u64),
    Table(Option<u64>),
}

/// The table options of `resolved` with shapes `shapes`, at wavelength step `step_nm` and phase
/// `phase_g`.
fn table_options(
    resolved: &Resolved,
    shapes: Shapes,
    media: &SkinMedia,
    step_nm: f64,
) -> TableOptions {
    let mut opts = TableOptions {
        step_nm,
        energy_tolerance: resolved.energy_tolerance,
        radial_error: resolved.radial_error,
        ..TableOptions::default()
    };
    opts.profile.phase_g = media.phase_g;
    opts.profile.surface = media.surface;
    match shapes {
        Shapes::Escapes(escapes) => opts.profile.exact_shape = ExactShape::MonteCarlo { escapes },
        Shapes::Table(Some(photons)) => {
            opts.profile.exact_shape = ExactShape::Table(ShapeTableOptions {
                photons,
                ..ShapeTableOptions::default()
            });
        }
        Shapes::Table(None) => {}
    }
    opts
}

/// Build (or read from the cache) the profile table of `params` (whose layers at their
/// Henyey–Greenstein g are `media`) with `method`, the shape knob and the fidelity `knobs`, and
/// record the choices.
pub fn skin_table(
    params: &SkinParams,
    media: &SkinMedia,
    method: Method,
    shape_escapes: Option<u64>,
    knobs: &FidelityKnobs,
) -> Result<(ProfileTable, SkinChoices), MultipoleError> {
    let t0 = Instant::now();
    let phase_g = media.phase_g;
    let resolved = resolve(knobs)?;
    let (dir, max_bytes) = cache_folder(knobs)?;
    let get = |shapes: Shapes| {
        // The key holds the options before the wavelength choice (the choice is part of the value).
        let probe = table_options(&resolved, shapes, media, 10.0);
        let key = table_key(params, method, &probe, resolved.step);
        let (stored, outcome) = cache::load_or_build(dir.as_deref(), max_bytes, &key, || {
            let wavelengths = match resolved.step {
                StepChoice::Fixed(step_nm) => WavelengthChoice::fixed(step_nm),
                StepChoice::Colour {
                    max_delta_e,
                    max_luminance_error,
                } => wavelengths::choose_step(
                    &wavelengths::totals_1nm(params, method, phase_g)?,
                    max_delta_e,
                    max_luminance_error,
                ),
            };
            let opts = table_options(&resolved, shapes, media, wavelengths.step_nm);
            let table = ProfileTable::build(params, method, &opts)?;
            Ok::<_, MultipoleError>(Stored { table, wavelengths })
        })?;
        Ok::<_, MultipoleError>((stored, outcome, probe))
    };
    let first = first_shapes(method, resolved.photons, shape_escapes);
    let (stored, outcome, probe, photon_choice) = match (method, resolved.photons) {
        (Method::Multipole, _) | (_, PhotonPolicy::Fixed) => {
            let (stored, outcome, probe) = get(first)?;
            (stored, outcome, probe, PhotonChoice::Fixed)
        }
        (_, PhotonPolicy::Override(_)) => {
            let (stored, outcome, probe) = get(first)?;
            (stored, outcome, probe, PhotonChoice::Override)
        }
        (_, PhotonPolicy::Footprint(footprint_mm)) => {
            // The share the footprint can see, from the cheapest table (`photons` module doc).
            let cheapest = photons::TABLE_PHOTON_LAW[0].0;
            let first = get(first)?;
            let (n, choice) = photons::choose(&first.0.table, footprint_mm, shape_escapes);
            let shapes = if shape_escapes.is_some() {
                Shapes::Escapes(n)
            } else {
                Shapes::Table(Some(n))
            };
            if shapes == Shapes::Table(Some(cheapest)) {
                (first.0, first.1, first.2, choice)
            } else {
                let (stored, outcome, probe) = get(shapes)?;
                (stored, outcome, probe, choice)
            }
        }
    };
    let table = stored.table;
    let r99_mm = table.largest_radius_for_energy_mm(0.99);
    let choices = SkinChoices {
        fidelity: knobs.fidelity.unwrap_or_default(),
        method,
        wavelengths: stored.wavelengths,
        energy_tolerance: resolved.energy_tolerance,
        r_out_mm: table.radii_mm().last().copied().unwrap_or(0.0),
        r99_mm,
        radii: table.radii_mm().len(),
        shape: shape_source(method, &probe),
        photons: photon_choice,
        // The band is placed on the radius the image's luminance sees (§16.3); the thin-part
        // walk keeps the widest row's, since transmission through a thin part is a red effect.
        lod: resolved.lod.map(|band| Lod {
            r99_mm: table.luminance_radius_for_energy_mm(0.99),
            band,
        }),
        transport: TransportChoice::bssrdf(
            media,
            resolved.thin_walk_r99.map(|k| k as f32 * r99_mm),
        ),
        cache: outcome,
        build_ms: 1e3 * t0.elapsed().as_secs_f64(),
        diffusion_failures: (method == Method::Multipole)
            .then(|| diffusion_failures(params, media))
            .flatten(),
        maps: None,
    };
    Ok((table, choices))
}

/// The choices of `knobs`, a knob out of range as the profile error naming it.
fn resolve(knobs: &FidelityKnobs) -> Result<Resolved, MultipoleError> {
    knobs.resolve().map_err(|e| MultipoleError::InvalidOption {
        name: e.name,
        value: e.value,
        range: e.range,
    })
}

/// The cache folder of skin tables under `knobs` (`None`: `--no-cache`, or no folder) and its
/// size limit, bytes.
pub(super) fn cache_folder(
    knobs: &FidelityKnobs,
) -> Result<(Option<PathBuf>, u64), MultipoleError> {
    let dir = knobs
        .cache
        .then(cache::cache_dir)
        .flatten()
        .map(|d| d.join("tables"));
    let max_bytes = cache::max_bytes().map_err(|e| MultipoleError::InvalidOption {
        name: "SKIN_CACHE_MAX_MIB",
        value: e.value.parse().unwrap_or(f64::NAN),
        range: "a whole number of MiB in [1, 1048576]",
    })?;
    Ok((dir, max_bytes))
}

/// The shapes of the first tables [`skin_table`] asks for: the fixed ones, the override, or the
/// cheapest table a footprint's choice is read from.
fn first_shapes(method: Method, photons: PhotonPolicy, shape_escapes: Option<u64>) -> Shapes {
    match (method, photons) {
        (Method::Multipole, _) | (_, PhotonPolicy::Fixed) => {
            shape_escapes.map_or(Shapes::Table(None), Shapes::Escapes)
        }
        (_, PhotonPolicy::Override(n)) => Shapes::Table(Some(n)),
        (_, PhotonPolicy::Footprint(_)) => Shapes::Table(Some(photons::TABLE_PHOTON_LAW[0].0)),
    }
}

/// The cache key of the first tables [`skin_table`] asks for with these inputs. With the photon
/// policy and the shape escapes (which pick any further tables from the first), it names every
/// table `skin_table` can return.
pub(super) fn first_table_key(
    params: &SkinParams,
    media: &SkinMedia,
    method: Method,
    shape_escapes: Option<u64>,
    knobs: &FidelityKnobs,
) -> Result<(String, PhotonPolicy), MultipoleError> {
    let resolved = resolve(knobs)?;
    let shapes = first_shapes(method, resolved.photons, shape_escapes);
    let probe = table_options(&resolved, shapes, media, 10.0);
    Ok((
        table_key(params, method, &probe, resolved.step),
        resolved.photons,
    ))
}

/// Where the profile shapes come from, in words.
fn shape_source(method: Method, opts: &TableOptions) -> String {
    match (method, opts.profile.exact_shape) {
        (Method::Multipole, _) => "multipole diffusion (no photons)".into(),
        (_, ExactShape::MonteCarlo { escapes }) => format!(
            "Monte Carlo, {escapes} escapes every {} nm",
            opts.profile.shape_step_nm
        ),
        (_, ExactShape::Table(t)) => {
            format!("universal table ({} white photons, cached)", t.photons)
        }
        (_, other) => format!("{other:?}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fidelity::Fidelity;
    use skin_io::cache::CacheOutcome;
    use skin_optics::Preset;

    /// A cache hit gives the table a rebuild gives, bit for bit, and a corrupted or truncated
    /// entry is rebuilt (the same bits again), never trusted.
    #[test]
    fn a_cache_hit_is_bit_identical_to_a_rebuild() {
        let dir = tempfile::tempdir().unwrap();
        let params = SkinParams::preset(Preset::Medium);
        for fidelity in [Fidelity::Auto, Fidelity::Full] {
            check_cache_round_trip(dir.path(), &params, fidelity);
        }
    }

    fn check_cache_round_trip(dir: &std::path::Path, params: &SkinParams, fidelity: Fidelity) {
        let knobs = FidelityKnobs {
            fidelity: Some(fidelity),
            ..FidelityKnobs::default()
        };
        let resolved = knobs.resolve().unwrap();
        let media = SkinMedia::new(params, multipole::DEFAULT_G).unwrap();
        let probe = table_options(&resolved, Shapes::Table(None), &media, 10.0);
        let k = table_key(params, Method::Exact, &probe, resolved.step);
        let build = || {
            let (t, c) = skin_table(
                params,
                &media,
                Method::Exact,
                None,
                &FidelityKnobs {
                    cache: false,
                    ..knobs
                },
            )?;
            Ok::<_, MultipoleError>(Stored {
                table: t,
                wavelengths: c.wavelengths,
            })
        };
        let fresh = build().unwrap();
        let (first, o) =
            cache::load_or_build(Some(dir), cache::DEFAULT_MAX_BYTES, &k, build).unwrap();
        assert!(matches!(o, CacheOutcome::Built(_)));
        let (hit, o) =
            cache::load_or_build(Some(dir), cache::DEFAULT_MAX_BYTES, &k, build).unwrap();
        assert!(matches!(o, CacheOutcome::Hit(_)), "{o:?}");
        assert_eq!(bits(&hit.table), bits(&fresh.table));
        assert_eq!(bits(&first.table), bits(&fresh.table));
        assert_eq!(hit.wavelengths, fresh.wavelengths);
        let path = cache::entry_path(dir, &k);
        let good = std::fs::read(&path).unwrap();
        let mut corrupt = good.clone();
        let mid = good.len() / 2;
        corrupt[mid] = if corrupt[mid] == b'1' { b'2' } else { b'1' };
        for bad in [corrupt, good[..good.len() / 3].to_vec()] {
            std::fs::write(&path, bad).unwrap();
            let (again, o) =
                cache::load_or_build(Some(dir), cache::DEFAULT_MAX_BYTES, &k, build).unwrap();
            assert!(matches!(o, CacheOutcome::Rebuilt(..)), "{o:?}");
            assert_eq!(bits(&again.table), bits(&fresh.table));
        }
    }

    /// Every value the renderer reads from the table, as bits: R(r) at every grid radius and every
    /// nm, and the totals.
    fn bits(t: &ProfileTable) -> Vec<u32> {
        (380..=780)
            .flat_map(|nm| {
                let nm = nm as f32;
                std::iter::once(t.total(nm)).chain(t.radii_mm().iter().map(move |&r| t.eval(nm, r)))
            })
            .map(f32::to_bits)
            .collect()
    }
}
