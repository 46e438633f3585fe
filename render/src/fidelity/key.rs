//! The disk-cache keys of a skin's tables and of a profile grid's record: the canonical bytes of
//! everything they depend on (the skin's parameters, the method, the table and profile knobs, the
//! wavelength choice and the format versions; for a grid, also its box, error target and
//! refinement constants), rendered as hex. Numbers enter as their IEEE-754 bits (little-endian),
//! choices as a fixed tag per variant, optional values behind a presence byte, so two inputs get
//! the same key exactly when every input is the same, on any machine and across releases that
//! keep [`KEY_FORMAT`].
//!
//! The option records are destructured field by field, so a field added to any of them fails to
//! compile here until it is part of the key (a variant added to a non-exhaustive enum keys by its
//! text). `SkinParams` keeps its fields private: its key reads
//! every accessor and every physiology extension, and a test checks that each number its `Debug`
//! shows is in the key.

use super::{PhotonPolicy, StepChoice};
use crate::bssrdf::TableOptions;
use multipole::diffusion::slab::Poles;
use multipole::diffusion::spatial::DiffusionOptions;
use multipole::skin::{ExactShape, ShapeTableOptions};
use multipole::{Method, ProfileOptions, Surface};
use skin_optics::SkinParams;
use skin_optics::physiology::Extension;

/// Version of this byte layout: bump it when the encoding below changes.
pub const KEY_FORMAT: u32 = 1;
/// Version of what a key builds: bump it whenever the same inputs give other tables (the exact
/// shape table's construction, a profile's sampling, ...).
pub const TABLES_VERSION: u32 = 3;

/// Version of what a grid record's key chooses: bump it whenever the same inputs and refinement
/// constants would choose another resolution (the error measure, the refinement's order, ...).
pub const GRID_VERSION: u32 = 1;

/// Canonical bytes, appended field by field.
#[derive(Debug, Default)]
struct Bytes(Vec<u8>);

impl Bytes {
    fn f64(&mut self, x: f64) -> &mut Self {
        self.0.extend_from_slice(&x.to_le_bytes());
        self
    }

    fn u64(&mut self, x: u64) -> &mut Self {
        self.0.extend_from_slice(&x.to_le_bytes());
        self
    }

    fn tag(&mut self, t: u8) -> &mut Self {
        self.0.push(t);
        self
    }

    fn opt_f64(&mut self, x: Option<f64>) -> &mut Self {
        match x {
            None => self.tag(0),
            Some(v) => self.tag(1).f64(v),
        }
    }

    fn text(&mut self, s: &str) -> &mut Self {
        self.u64(s.len() as u64);
        self.0.extend_from_slice(s.as_bytes());
        self
    }

    fn hex(&self) -> String {
        // Two digits a byte without a formatter: a grid's load makes a key per node.
        const DIGITS: &[u8; 16] = b"0123456789abcdef";
        let mut out = String::with_capacity(2 * self.0.len());
        for &b in &self.0 {
            out.push(char::from(DIGITS[usize::from(b >> 4)]));
            out.push(char::from(DIGITS[usize::from(b & 15)]));
        }
        out
    }
}

/// The cache key of the tables of `params` by `method` with table knobs `opts` and wavelength
/// choice `step`.
#[must_use]
pub fn table_key(
    params: &SkinParams,
    method: Method,
    opts: &TableOptions,
    step: StepChoice,
) -> String {
    let mut b = Bytes::default();
    b.u64(u64::from(KEY_FORMAT))
        .u64(u64::from(TABLES_VERSION))
        .text(env!("CARGO_PKG_VERSION"));
    skin(&mut b, params);
    match method {
        Method::Exact => b.tag(0),
        Method::Multipole => b.tag(1),
        // A variant added later (the enum is non-exhaustive) keys by its name.
        other => b.tag(255).text(&other.to_string()),
    };
    table(&mut b, opts);
    match step {
        StepChoice::Fixed(nm) => b.tag(0).f64(nm),
        StepChoice::Colour {
            max_delta_e,
            max_luminance_error,
        } => b.tag(1).f64(max_delta_e).f64(max_luminance_error),
    };
    format!("skin-tables {}", b.hex())
}

/// The cache key of the record of a profile grid (`super::grid`) over the parameter box `range`
/// (per axis [lo, hi]) at error target `target`: `node`, the key of the first tables of its
/// lowest node (`super::tables::first_table_key`: the skin, method and every table knob), the
/// photon policy and shape escapes that pick each node's further tables, and the refinement's
/// constants `refinement`.
#[must_use]
pub fn grid_key(
    node: &str,
    photons: PhotonPolicy,
    shape_escapes: Option<u64>,
    range: [[f32; 2]; 3],
    target: f32,
    refinement: &[f64],
) -> String {
    let mut b = Bytes::default();
    b.u64(u64::from(KEY_FORMAT)).u64(u64::from(GRID_VERSION));
    match photons {
        PhotonPolicy::Fixed => b.tag(0),
        PhotonPolicy::Override(n) => b.tag(1).u64(n),
        PhotonPolicy::Footprint(mm) => b.tag(2).f64(f64::from(mm)),
    };
    match shape_escapes {
        None => b.tag(0),
        Some(n) => b.tag(1).u64(n),
    };
    for [lo, hi] in range {
        b.f64(f64::from(lo)).f64(f64::from(hi));
    }
    b.f64(f64::from(target)).u64(refinement.len() as u64);
    for &x in refinement {
        b.f64(x);
    }
    format!("skin-grid {} {node}", b.hex())
}

fn skin(b: &mut Bytes, p: &SkinParams) {
    b.f64(p.melanin())
        .f64(p.eumelanin_blend())
        .f64(p.hemoglobin())
        .f64(p.oiliness())
        .f64(p.oxygenation())
        .f64(p.epidermis_thickness_mm())
        .f64(p.eta())
        .f64(p.dermis_scattering_scale());
    let physiology = p.physiology();
    b.u64(Extension::ALL.len() as u64);
    for e in Extension::ALL {
        b.f64(physiology.get(e));
    }
}

fn table(b: &mut Bytes, opts: &TableOptions) {
    let TableOptions {
        from_nm,
        to_nm,
        step_nm,
        radii,
        energy_tolerance,
        radial_error,
        profile: p,
    } = opts;
    b.f64(*from_nm)
        .f64(*to_nm)
        .f64(*step_nm)
        .u64(*radii as u64)
        .opt_f64(*energy_tolerance)
        .opt_f64(*radial_error);
    profile(b, p);
}

fn profile(b: &mut Bytes, p: &ProfileOptions) {
    let ProfileOptions {
        diffusion:
            DiffusionOptions {
                poles,
                radial_samples,
                r_max_mm,
                energy_fraction,
                transform_nodes,
                transform_radii,
                transform_tolerance,
            },
        exact_shape,
        shape_step_nm,
        phase_g,
        surface,
    } = p;
    match poles {
        Poles::Exact => b.tag(0),
        Poles::Count(n) => b.tag(1).u64(*n as u64),
    };
    b.u64(*radial_samples as u64)
        .opt_f64(*r_max_mm)
        .f64(*energy_fraction)
        .u64(*transform_nodes as u64)
        .u64(*transform_radii as u64)
        .f64(*transform_tolerance);
    match exact_shape {
        ExactShape::RescaledTotal => b.tag(0),
        ExactShape::PerLayer => b.tag(1),
        ExactShape::MonteCarlo { escapes } => b.tag(2).u64(*escapes),
        ExactShape::Table(t) => {
            let ShapeTableOptions {
                photons,
                depths_per_octave,
                radial_per_decade,
                alpha_per_decade,
                seed,
            } = t;
            b.tag(3)
                .u64(*photons)
                .u64(u64::from(*depths_per_octave))
                .u64(u64::from(*radial_per_decade))
                .u64(u64::from(*alpha_per_decade))
                .u64(*seed)
        }
        // A variant added later (the enum is non-exhaustive) keys by its debug text.
        other => b.tag(255).text(&format!("{other:?}")),
    };
    b.f64(*shape_step_nm).f64(*phase_g);
    match surface {
        Surface::Fresnel => b.tag(0),
        Surface::Lobe {
            roughness_m,
            oiliness_rho_s,
        } => b.tag(1).f64(*roughness_m).f64(*oiliness_rho_s),
    };
}

#[cfg(test)]
mod tests {
    use super::*;
    use skin_optics::physiology::Physiology;

    fn key_of(params: &SkinParams, opts: &TableOptions) -> String {
        table_key(params, Method::Exact, opts, StepChoice::Fixed(10.0))
    }

    /// Every number `SkinParams`'s `Debug` shows (all of them distinct here) is in the key as its
    /// bits: a field added to `SkinParams` and left out of the key fails this test.
    #[test]
    fn the_key_holds_every_skin_number() {
        let mut physiology = Physiology::SEED;
        for (e, v) in Extension::ALL.into_iter().zip([0.011, 0.37, 1.13, 0.87]) {
            physiology = physiology.with(e, v).unwrap();
        }
        let params = SkinParams::new(0.123, 0.61, 0.047, 0.29)
            .unwrap()
            .with_oxygenation(0.66)
            .unwrap()
            .with_epidermis_thickness_mm(0.21)
            .unwrap()
            .with_eta(1.37)
            .unwrap()
            .with_dermis_scattering_scale(1.09)
            .unwrap()
            .with_physiology(physiology);
        let key = key_of(&params, &TableOptions::default());
        let debug = format!("{params:?}");
        let numbers: Vec<f64> = debug
            .split(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-' || c == 'e'))
            .filter_map(|t| t.parse::<f64>().ok())
            .collect();
        assert_eq!(numbers.len(), 12, "{debug}");
        for x in numbers {
            let hex: String = x.to_le_bytes().iter().map(|b| format!("{b:02x}")).collect();
            assert!(key.contains(&hex), "{x} of {debug} missing from the key");
        }
    }

    /// Each input moves the key; equal inputs give equal keys.
    #[test]
    fn each_input_changes_the_key() {
        let params = SkinParams::preset(skin_optics::Preset::Medium);
        let base = TableOptions::default();
        let k = key_of(&params, &base);
        assert_eq!(k, key_of(&params, &base.clone()));
        let mut other = base.clone();
        other.profile.phase_g = 0.85;
        let mut photons = base.clone();
        photons.profile.exact_shape = ExactShape::Table(ShapeTableOptions {
            photons: 123_456,
            ..ShapeTableOptions::default()
        });
        let mut tol = base.clone();
        tol.energy_tolerance = Some(1e-3);
        let lighter = SkinParams::preset(skin_optics::Preset::Light);
        let keys = [
            key_of(&params, &other),
            key_of(&params, &photons),
            key_of(&params, &tol),
            key_of(&lighter, &base),
            table_key(&params, Method::Multipole, &base, StepChoice::Fixed(10.0)),
            table_key(&params, Method::Exact, &base, StepChoice::Fixed(20.0)),
        ];
        for (i, a) in keys.iter().enumerate() {
            assert_ne!(a, &k, "input {i}");
            for b in &keys[i + 1..] {
                assert_ne!(a, b);
            }
        }
    }

    /// Each input of a grid record moves its key; equal inputs give equal keys.
    #[test]
    fn each_grid_input_changes_the_grid_key() {
        let node = key_of(
            &SkinParams::preset(skin_optics::Preset::Medium),
            &TableOptions::default(),
        );
        let range = [[0.01, 0.4], [0.6, 0.6], [0.001, 0.2]];
        let grid = |node: &str, photons, escapes, range, target, refinement: &[f64]| {
            grid_key(node, photons, escapes, range, target, refinement)
        };
        let base = grid(&node, PhotonPolicy::Fixed, None, range, 0.02, &[33.0]);
        assert_eq!(
            base,
            grid(&node, PhotonPolicy::Fixed, None, range, 0.02, &[33.0])
        );
        let mut wider = range;
        wider[2][1] = 0.25;
        let other_node = key_of(
            &SkinParams::preset(skin_optics::Preset::Light),
            &TableOptions::default(),
        );
        let keys = [
            grid(&other_node, PhotonPolicy::Fixed, None, range, 0.02, &[33.0]),
            grid(
                &node,
                PhotonPolicy::Footprint(1.5),
                None,
                range,
                0.02,
                &[33.0],
            ),
            grid(
                &node,
                PhotonPolicy::Override(50_000),
                None,
                range,
                0.02,
                &[33.0],
            ),
            grid(&node, PhotonPolicy::Fixed, Some(1000), range, 0.02, &[33.0]),
            grid(&node, PhotonPolicy::Fixed, None, wider, 0.02, &[33.0]),
            grid(&node, PhotonPolicy::Fixed, None, range, 0.03, &[33.0]),
            grid(&node, PhotonPolicy::Fixed, None, range, 0.02, &[17.0]),
        ];
        for (i, a) in keys.iter().enumerate() {
            assert_ne!(a, &base, "input {i}");
            for b in &keys[i + 1..] {
                assert_ne!(a, b);
            }
        }
    }
}
