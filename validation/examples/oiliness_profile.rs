//! Why ρ_s so often fits to 0 under SCI (docs/physics.md §13.4): the `auto` fit of exploration
//! records with ρ_s free against the same fit with ρ_s held at 0, 0.25 (the paper's and the light
//! preset's), 0.5 and 1 (a(cos 8°) ≈ F(0): the whole Fresnel reflection of the surface, what a
//! bare η = 1.4 surface returns into an SCI sphere). For each: RMS median and p90, and the median
//! χ² cost of holding ρ_s, n (rms_fixed² − rms_free²) / σ², against the criterion's price of one
//! parameter, ln n; plus how often the scattering scales sit on their lower bound.
//!
//!     cargo run --release -p validation --features studies --example oiliness_profile [-- RECORDS]
//!
//! Exploration records only (the held-out ones are for reporting), spread evenly (default 24).

use skin_fit::{FitOptions, Geometry, MeasuredOptions, ModelChoice, Parameter};
use skin_optics::{Extension, SkinParams};
use validation::measured::{EXPLORE_CSV, fit_records, parse_records, quantile};

fn main() -> anyhow::Result<()> {
    let limit: usize = std::env::args().nth(1).map_or(Ok(24), |s| s.parse())?;
    let all = parse_records(EXPLORE_CSV)?;
    let stride = all.len() as f64 / limit.min(all.len()) as f64;
    let records: Vec<_> = (0..limit.min(all.len()))
        .map(|i| all[(i as f64 * stride) as usize].clone())
        .collect();
    let opts = |rho: Option<f64>| MeasuredOptions {
        geometry: Geometry::Sci,
        model: ModelChoice::Auto,
        fit_oiliness: rho.is_none(),
        fit: FitOptions {
            beta_scan: 0,
            base: SkinParams::default()
                .with_oiliness(rho.unwrap_or(0.25))
                .expect("ρ_s in [0, 1]"),
            ..FitOptions::default()
        },
        ..MeasuredOptions::default()
    };
    let free = fit_records(&records, &opts(None))?;
    let sigma: f64 = 0.005;
    let n = records[0].spectrum.len() as f64;
    let low = |fits: &[validation::measured::RecordFit], p: Parameter| {
        fits.iter()
            .filter(|f| f.fit.at_bounds().contains(&(p, 0.5)))
            .count()
    };
    let rayleigh = Parameter::Extended(Extension::RayleighScale);
    println!(
        "| ρ_s | RMS median | RMS p90 | median χ² cost vs free (ln n = {:.1}) | cost < ln n | Rayleigh at 0.5 | dermis scattering at 0.5 |",
        n.ln()
    );
    println!("|---|---|---|---|---|---|---|");
    let rho_free: Vec<f64> = free.iter().map(|f| f.fit.skin.oiliness()).collect();
    for rho in [None, Some(0.0), Some(0.25), Some(0.5), Some(1.0)] {
        let fits = if rho.is_none() {
            free.clone()
        } else {
            fit_records(&records, &opts(rho))?
        };
        let rms: Vec<f64> = fits.iter().map(|f| f.fit.rms).collect();
        let cost: Vec<f64> = fits
            .iter()
            .zip(&free)
            .map(|(a, b)| n * (a.fit.rms.powi(2) - b.fit.rms.powi(2)) / sigma.powi(2))
            .collect();
        println!(
            "| {} | {:.4} | {:.4} | {:.1} | {}/{} | {} | {} |",
            rho.map_or("free".to_string(), |r| format!("{r}")),
            quantile(&rms, 0.5),
            quantile(&rms, 0.9),
            quantile(&cost, 0.5),
            cost.iter().filter(|&&c| c < n.ln()).count(),
            cost.len(),
            low(&fits, rayleigh),
            low(&fits, Parameter::DermisScattering),
        );
    }
    println!(
        "free ρ_s: median {:.2}, at 0 in {}/{}",
        quantile(&rho_free, 0.5),
        rho_free.iter().filter(|&&r| r <= 1e-3).count(),
        rho_free.len()
    );
    Ok(())
}
