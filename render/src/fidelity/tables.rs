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
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub(super) enum Shapes {
    /// This many escapes per Monte Carlo shape.
    Escapes(u64),
    /// The universal table of this many photons (`None`: the default).
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

/// Where a skin's tables are looked up: its inputs, resolved, and the cache folder.
struct Lookup<'a> {
    params: &'a SkinParams,
    media: &'a SkinMedia,
    method: Method,
    resolved: Resolved,
    dir: Option<PathBuf>,
    max_bytes: u64,
}

/// Tables found through the cache: the entry, what the cache did, the options before the
/// wavelength choice, and the shapes they were built with.
struct Found {
    stored: Stored,
    outcome: cache::CacheOutcome,
    probe: TableOptions,
    shapes: Shapes,
}

impl<'a> Lookup<'a> {
    fn new(
        params: &'a SkinParams,
        media: &'a SkinMedia,
        method: Method,
        knobs: &FidelityKnobs,
    ) -> Result<Self, MultipoleError> {
        let resolved = resolve(knobs)?;
        let (dir, max_bytes) = cache_folder(knobs)?;
        Ok(Self {
            params,
            media,
            method,
            resolved,
            dir,
            max_bytes,
        })
    }

    /// The tables with shapes `shapes`, read or built and stored.
    fn get(&self, shapes: Shapes) -> Result<Found, MultipoleError> {
        let (params, method, resolved) = (self.params, self.method, &self.resolved);
        // The key holds the options before the wavelength choice (the choice is part of the value).
        let probe = table_options(resolved, shapes, self.media, 10.0);
        let key = table_key(params, method, &probe, resolved.step);
        let (stored, outcome) =
            cache::load_or_build(self.dir.as_deref(), self.max_bytes, &key, || {
                let wavelengths = match resolved.step {
                    StepChoice::Fixed(step_nm) => WavelengthChoice::fixed(step_nm),
                    StepChoice::Colour {
                        max_delta_e,
                        max_luminance_error,
                    } => wavelengths::choose_step(
                        &wavelengths::totals_1nm(params, method, self.media.phase_g)?,
                        max_delta_e,
                        max_luminance_error,
                    ),
                };
                let opts = table_options(resolved, shapes, self.media, wavelengths.step_nm);
                let table = ProfileTable::build(params, method, &opts)?;
                Ok::<_, MultipoleError>(Stored { table, wavelengths })
            })?;
        Ok(Found {
            stored,
            outcome,
            probe,
            shapes,
        })
    }

    /// The tables the photon policy chooses, and the record of the choice.
    fn choose(&self, shape_escapes: Option<u64>) -> Result<(Found, PhotonChoice), MultipoleError> {
        let first = first_shapes(self.method, self.resolved.photons, shape_escapes);
        match (self.method, self.resolved.photons) {
            (Method::Multipole, _) | (_, PhotonPolicy::Fixed) => {
                Ok((self.get(first)?, PhotonChoice::Fixed))
            }
            (_, PhotonPolicy::Override(_)) => Ok((self.get(first)?, PhotonChoice::Override)),
            (_, PhotonPolicy::Footprint(footprint_mm)) => {
                // The share the footprint can see, from the cheapest table (`photons` module doc).
                let first = self.get(first)?;
                let (n, choice) = photons::choose(&first.stored.table, footprint_mm, shape_escapes);
                let shapes = if shape_escapes.is_some() {
                    Shapes::Escapes(n)
                } else {
                    Shapes::Table(Some(n))
                };
                if shapes == first.shapes {
                    Ok((first, choice))
                } else {
                    Ok((self.get(shapes)?, choice))
                }
            }
        }
    }
}

/// The table of one node of a profile grid (`super::grid`): [`skin_table`]'s, without the record
/// of choices, and the shapes it was built with. With `known` shapes (a grid record's) only that
/// entry is read: a footprint's choice needs the cheapest table read first.
pub(super) fn node_table(
    params: &SkinParams,
    media: &SkinMedia,
    method: Method,
    shape_escapes: Option<u64>,
    knobs: &FidelityKnobs,
    known: Option<Shapes>,
) -> Result<(ProfileTable, Shapes), MultipoleError> {
    let lookup = Lookup::new(params, media, method, knobs)?;
    let found = match known {
        Some(shapes) => lookup.get(shapes)?,
        None => lookup.choose(shape_escapes)?.0,
    };
    Ok((found.stored.table, found.shapes))
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
    let lookup = Lookup::new(params, media, method, knobs)?;
    let resolved = lookup.resolved;
    let (
        Found {
            stored,
            outcome,
            probe,
            ..
        },
        photon_choice,
    ) = lookup.choose(shape_escapes)?;
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

/// `build` given the cache folder of skin tables under `knobs` and its size limit
/// ([`cache_folder`]): what builds through the disk cache in a folder it is handed.
pub(super) fn in_cache_folder<T>(
    knobs: &FidelityKnobs,
    build: impl FnOnce(Option<&std::path::Path>, u64) -> Result<T, MultipoleError>,
) -> Result<T, MultipoleError> {
    let (dir, max_bytes) = cache_folder(knobs)?;
    build(dir.as_deref(), max_bytes)
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

/// Whether the photon policy `photons` could choose `shapes` for some skin, with the shape
/// escapes `shape_escapes` and `method` (a grid record's shapes are checked against it).
pub(super) fn may_choose(
    method: Method,
    photons: PhotonPolicy,
    shape_escapes: Option<u64>,
    shapes: Shapes,
) -> bool {
    match (method, photons, shape_escapes, shapes) {
        (Method::Multipole, ..) | (_, PhotonPolicy::Fixed | PhotonPolicy::Override(_), ..) => {
            shapes == first_shapes(method, photons, shape_escapes)
        }
        (_, PhotonPolicy::Footprint(_), Some(asked), Shapes::Escapes(n)) => {
            (photons::MIN_ESCAPES.min(asked)..=asked).contains(&n)
        }
        (_, PhotonPolicy::Footprint(_), None, Shapes::Table(Some(n))) => {
            photons::TABLE_PHOTON_LAW.iter().any(|&(p, _)| p == n)
        }
        _ => false,
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

    /// A grid record's shapes are trusted only where the policy could choose them: the fixed
    /// and overridden policies their one choice, a footprint a rung of the photon law (table) or
    /// a count between the least escapes and those asked for.
    #[test]
    fn recorded_shapes_are_checked_against_the_policy() {
        use PhotonPolicy::{Fixed, Footprint, Override};
        let (exact, mp) = (Method::Exact, Method::Multipole);
        let table = |n| Shapes::Table(Some(n));
        let (foot, esc) = (Footprint(1.0), Shapes::Escapes);
        let cases = [
            (exact, Fixed, None, Shapes::Table(None), true),
            (exact, Fixed, None, table(50_000), false),
            (exact, Fixed, Some(1000), esc(1000), true),
            (exact, Fixed, Some(1000), esc(999), false),
            (exact, Override(77_000), None, table(77_000), true),
            (exact, Override(77_000), None, table(50_000), false),
            (mp, foot, None, Shapes::Table(None), true),
            (mp, foot, None, table(50_000), false),
            (exact, foot, None, table(50_000), true),
            (exact, foot, None, table(200_000), true),
            (exact, foot, None, table(60_000), false),
            (exact, foot, None, Shapes::Table(None), false),
            (exact, foot, Some(5000), esc(5000), true),
            (exact, foot, Some(5000), esc(100), true),
            (exact, foot, Some(5000), esc(99), false),
            (exact, foot, Some(5000), esc(5001), false),
            (exact, foot, Some(5000), table(50_000), false),
        ];
        for (method, policy, escapes, shapes, want) in cases {
            assert_eq!(
                may_choose(method, policy, escapes, shapes),
                want,
                "{method:?} {policy:?} {escapes:?} {shapes:?}"
            );
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
