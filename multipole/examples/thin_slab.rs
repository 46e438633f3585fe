//! Thin-slab behaviour: total R and T of a slab against its thickness in mean free paths, for the raw
//! multipole of docs/physics.md §4 (source at ℓ, 11 pairs, no treatment) and for this crate's documented
//! treatment (`Slab`: diffused fraction w = min(1, σs'd), source at ℓw², delta pass-through).
//!
//! `cargo run --release -p multipole --features studies --example thin_slab [OUT.csv]` (default `out/multipole_thin_slab.csv`).
//! Slab: σa = 0.1, σs' = 2 mm⁻¹ (ℓ = 0.476 mm), η_top = 1.4, η_bottom = 1; also σa = 0 (energy check).

#[path = "shared/write.rs"]
mod shared;

use multipole::diffusion::boundary::a_coefficient;
use multipole::diffusion::medium::pole_transform;
use multipole::diffusion::{
    medium::Medium,
    slab::{Poles, Slab},
};

/// The untreated 11-pair multipole totals (R, T) at q = 0.
fn raw(m: &Medium, d: f64) -> (f64, f64) {
    let (l, st) = (m.mean_free_path_mm(), m.sigma_tr());
    let (zb0, zbd) = (
        m.extrapolation_mm(a_coefficient(1.4)),
        m.extrapolation_mm(1.0),
    );
    let period = 2.0 * (d + zb0 + zbd);
    let (mut r, mut t) = (0.0, 0.0);
    for i in -5i64..=5 {
        let (zr, zv) = (i as f64 * period + l, i as f64 * period - l - 2.0 * zb0);
        r += pole_transform(zr, st) - pole_transform(zv, st);
        t += pole_transform(d - zr, st) - pole_transform(d - zv, st);
    }
    (0.5 * m.albedo_prime() * r, 0.5 * m.albedo_prime() * t)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "out/multipole_thin_slab.csv".into());
    let mut csv = String::from(
        "sigma_a_per_mm,d_over_mfp,raw_r,raw_t,raw_r_plus_t,treated_r,treated_t,treated_r_plus_t,scattered_weight\n",
    );
    for sa in [0.1, 0.0] {
        let m = Medium::new(sa, 2.0)?;
        for k in 0..=60 {
            let mfp = 0.01 * 10f64.powf(k as f64 * 2.7 / 60.0); // 0.01 … 5 mean free paths
            let d = mfp * m.mean_free_path_mm();
            // At σa = 0 the 11-pair sum does not converge (σtr = 0): raw columns left empty.
            let raw_cols = if sa > 0.0 {
                let (rr, rt) = raw(&m, d);
                format!("{rr:.6},{rt:.6},{:.6}", rr + rt)
            } else {
                ",,".to_string()
            };
            let s = Slab::new(m, d, 1.4, 1.0)?;
            let (tr, tt) = s.transform(0.0, Poles::Exact);
            csv.push_str(&format!(
                "{sa},{mfp:.5},{raw_cols},{tr:.6},{tt:.6},{:.6},{:.5}\n",
                tr + tt,
                s.scattered_weight()
            ));
        }
    }
    shared::write_atomically(std::path::Path::new(&out), csv.as_bytes())?;
    Ok(())
}
