//! Monte Carlo shape photons from the pixel footprint (docs/physics.md §16.6). The exact profile's
//! radial shape comes from photons (the universal white-Monte-Carlo table, or run-time escapes), and
//! its error is Monte Carlo noise that falls as 1/√photons. A pixel of footprint F integrates the
//! profile over itself: light that leaves within F/2 of where it entered lands, on average, in the
//! pixel it entered, so a shape error that moves energy among radii below F/2 changes no pixel.
//! What the image can show is the shape error on the share of the energy beyond F/2,
//!
//!   s(F) = 1 − E(F/2) / R_tot   (the largest over the table's rows),
//!
//! so the shape may be 1/s(F) times as noisy as the close-up's and look the same. The close-up's
//! error is the default table's (500,000 photons, worst 2.50%); at footprint F the tolerance is
//! 2.50% / s(F), and the table takes the fewest photons whose measured worst error meets it.
//!
//! The measured law (energy-weighted Σ|E_model − E_mc| / R_mc on 0.02-mm annuli to 6 mm against
//! 10⁶-photon layered Monte Carlo runs, worst of light/medium/dark at 450/550/650 nm;
//! `skin-validate table-knobs`, BENCHMARKS.md "Exact profile table") is [`TABLE_PHOTON_LAW`]. The
//! run-time Monte Carlo shape (`--shape-escapes N`) is scaled by the same criterion through its own
//! 1/√escapes law: N·s(F)² escapes keep s(F) × error constant, at least [`MIN_ESCAPES`].
//!
//! s(F) is read from the cheapest table ([`TABLE_PHOTON_LAW`]'s first rung): its cumulative energy
//! at F/2 is far more accurate than the choice needs (a share, not a shape). The smallest footprint
//! on a skin is the camera's pixel angle times the distance from the camera to the nearest point of
//! the bounding box of that skin's meshes: a lower bound on every camera hit's footprint, so the
//! choice never takes fewer photons than the nearest pixel allows.

use crate::bssrdf::ProfileTable;
use serde::{Deserialize, Serialize};

/// Photons of the universal shape table and the worst energy-weighted shape error measured at
/// that count (fractions; `skin-validate table-knobs`, BENCHMARKS.md "Exact profile table"),
/// fewest first; the last is the default table.
pub const TABLE_PHOTON_LAW: [(u64, f64); 3] =
    [(50_000, 0.0645), (200_000, 0.0337), (500_000, 0.0250)];

/// Fewest run-time escapes a footprint may scale a Monte Carlo shape down to (the knob's minimum).
pub const MIN_ESCAPES: u64 = 100;

/// How the shape photons were chosen, for `--explain`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum PhotonChoice {
    /// The fidelity's fixed count (full fidelity, the diffusion method, or no footprint known).
    Fixed,
    /// Set by `--shape-photons` or `fidelity.shape_photons`.
    Override,
    /// From the smallest pixel footprint on the skin.
    Footprint {
        /// Smallest pixel footprint on the skin, mm.
        footprint_mm: f32,
        /// s(F): largest share of a row's energy beyond half the footprint.
        visible_share: f32,
        /// The shape error the footprint allows, a fraction.
        tolerance: f64,
        /// The measured worst shape error at the chosen count (table), a fraction; for run-time
        /// escapes, the error relative to the count asked for.
        measured: f64,
    },
}

/// s(F) of `table`: the largest share, over its rows, of a row's energy beyond `r_mm` (by
/// bisection on the monotone inverse cumulative, 40 halvings: below f32's resolution).
#[must_use]
pub fn share_beyond(table: &ProfileTable, r_mm: f32) -> f32 {
    if r_mm <= 0.0 {
        return 1.0;
    }
    // f_in: the largest energy fraction every row holds within r_mm.
    let (mut lo, mut hi) = (0.0f32, 1.0f32);
    for _ in 0..40 {
        let mid = 0.5 * (lo + hi);
        if table.largest_radius_for_energy_mm(mid) <= r_mm {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    (1.0 - lo).clamp(0.0, 1.0)
}

/// The shape error a footprint whose visible share is `visible_share` allows: the default table's
/// error divided by the share (∞ when nothing is visible).
#[must_use]
pub fn tolerance(visible_share: f32) -> f64 {
    let close_up = TABLE_PHOTON_LAW[TABLE_PHOTON_LAW.len() - 1].1;
    close_up / f64::from(visible_share).max(1e-9)
}

/// The fewest table photons whose measured error meets [`tolerance`]`(visible_share)`, and that
/// error.
#[must_use]
pub fn table_photons(visible_share: f32) -> (u64, f64) {
    let tol = tolerance(visible_share);
    TABLE_PHOTON_LAW
        .into_iter()
        .find(|&(_, e)| e <= tol)
        .unwrap_or(TABLE_PHOTON_LAW[TABLE_PHOTON_LAW.len() - 1])
}

/// Run-time Monte Carlo escapes for a shape asked at `escapes` seen with visible share
/// `visible_share`: escapes·s², within [[`MIN_ESCAPES`], escapes].
#[must_use]
pub fn scaled_escapes(escapes: u64, visible_share: f32) -> u64 {
    let s = f64::from(visible_share.clamp(0.0, 1.0));
    ((escapes as f64 * s * s).ceil() as u64).clamp(MIN_ESCAPES.min(escapes), escapes)
}

/// The photon count for a skin whose smallest pixel footprint is `footprint_mm` and whose cheapest
/// table (`TABLE_PHOTON_LAW[0]`) is `cheapest`: run-time escapes scaled from `escapes` when given,
/// else the table photons; and the record of why.
#[must_use]
pub fn choose(
    cheapest: &ProfileTable,
    footprint_mm: f32,
    escapes: Option<u64>,
) -> (u64, PhotonChoice) {
    let visible_share = share_beyond(cheapest, 0.5 * footprint_mm);
    let (n, measured) = match escapes {
        // 1/√escapes: the error relative to the count asked for.
        Some(asked) => {
            let n = scaled_escapes(asked, visible_share);
            (n, (asked as f64 / n as f64).sqrt())
        }
        None => table_photons(visible_share),
    };
    let choice = PhotonChoice::Footprint {
        footprint_mm,
        visible_share,
        tolerance: tolerance(visible_share),
        measured,
    };
    (n, choice)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The law is ordered (more photons, less error) and the default is its last rung; a close-up
    /// (everything visible) keeps the default, a footprint that sees a tenth of the energy takes
    /// the cheapest rung, whose measured error is within its tolerance; every chosen error meets
    /// its tolerance wherever one does.
    #[test]
    fn fewer_photons_where_less_is_visible() {
        assert!(
            TABLE_PHOTON_LAW
                .windows(2)
                .all(|w| w[0].0 < w[1].0 && w[0].1 > w[1].1)
        );
        assert_eq!(
            TABLE_PHOTON_LAW[2].0,
            multipole::skin::ShapeTableOptions::default().photons
        );
        assert_eq!(table_photons(1.0).0, 500_000);
        let (n, e) = table_photons(0.1);
        assert_eq!(n, 50_000);
        assert!(e <= tolerance(0.1));
        // More visible energy never takes fewer photons.
        let mut last = 0;
        for i in 1..=100 {
            let s = i as f32 / 100.0;
            let (n, e) = table_photons(s);
            assert!(e <= tolerance(s), "share {s}: error {e}");
            assert!(n >= last, "share {s}: {n} photons after {last}");
            last = n;
        }
        // Escapes: s² scaling, floored, never above the request.
        assert_eq!(scaled_escapes(4000, 1.0), 4000);
        assert_eq!(scaled_escapes(4000, 0.5), 1000);
        assert_eq!(scaled_escapes(4000, 0.01), MIN_ESCAPES);
        assert_eq!(scaled_escapes(50, 0.01), 50);
    }
}
