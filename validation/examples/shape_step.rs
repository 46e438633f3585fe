//! Cost and error of the Monte Carlo shape knobs of `SpectralProfiles` (the renderer's tables):
//! escaping photons per shape and the wavelength step between shapes (rows in between mix the two
//! neighbouring shapes). Error: energy-weighted L1 distance Σ|E − E_ref| / R_ref over geometric
//! annuli (10⁻³–50 mm) of each row against a direct Monte Carlo shape with 16,000 escapes at the
//! same wavelength, at 390, 430, …, 750 nm (between anchors for every step ≥ 20 nm: interpolation
//! error included), for the light, medium and dark presets. Time: wall clock of the whole 380–780 nm,
//! 10 nm table on all cores.
//!
//! `cargo run --release -p validation --features studies --example shape_step`

use multipole::skin::{ExactShape, Method, SpectralProfiles, exact_profile};
use multipole::{Profile, ProfileOptions};
use skin_optics::{Preset, SkinParams, WavelengthGrid};

fn distance(p: &Profile, reference: &Profile) -> f64 {
    let edges: Vec<f64> = (0..=400)
        .map(|i| 1e-3 * (5e4f64).powf(i as f64 / 400.0))
        .collect();
    let energy = |q: &Profile, a: f64, b: f64| {
        let h = (b - a) / 8.0;
        (0..8)
            .map(|k| {
                let r = a + (k as f64 + 0.5) * h;
                2.0 * std::f64::consts::PI * r * q.eval(r) * h
            })
            .sum::<f64>()
    };
    let head = (energy(p, 0.0, edges[0]) - energy(reference, 0.0, edges[0])).abs();
    let rest: f64 = edges
        .windows(2)
        .map(|w| (energy(p, w[0], w[1]) - energy(reference, w[0], w[1])).abs())
        .sum();
    (head + rest) / reference.total()
}

fn main() -> anyhow::Result<()> {
    let grid = WavelengthGrid::new(380.0, 780.0, 10.0)?;
    let knobs: [(u64, f64); 5] = [
        (4_000, 10.0),
        (2_000, 20.0),
        (1_000, 20.0),
        (2_000, 40.0),
        (1_000, 40.0),
    ];
    println!("| preset | escapes | shape step (nm) | table time (s) | mean error | max error |");
    println!("| --- | --- | --- | --- | --- | --- |");
    for preset in [Preset::Light, Preset::Medium, Preset::Dark] {
        let skin = SkinParams::preset(preset);
        // 390, 430, …, 750 nm: between two anchors for every step of 20 nm or more.
        let mids: Vec<usize> = (0..grid.len()).filter(|i| i % 4 == 1).collect();
        let references = mids
            .iter()
            .map(|&i| {
                exact_profile(
                    &skin,
                    grid.wavelength(i),
                    ExactShape::MonteCarlo { escapes: 16_000 },
                    &ProfileOptions::default(),
                )
            })
            .collect::<Result<Vec<_>, _>>()?;
        for (escapes, step) in knobs {
            let opts = ProfileOptions {
                exact_shape: ExactShape::MonteCarlo { escapes },
                shape_step_nm: step,
                ..ProfileOptions::default()
            };
            let t0 = std::time::Instant::now();
            let set = SpectralProfiles::new(&skin, &grid, Method::Exact, &opts)?;
            let secs = t0.elapsed().as_secs_f64();
            let errors: Vec<f64> = mids
                .iter()
                .zip(&references)
                .map(|(&i, r)| distance(set.profile(i), r))
                .collect();
            let mean = errors.iter().sum::<f64>() / errors.len() as f64;
            let max = errors.iter().copied().fold(0.0, f64::max);
            println!(
                "| {preset:?} | {escapes} | {step} | {secs:.2} | {:.1}% | {:.1}% |",
                100.0 * mean,
                100.0 * max
            );
        }
    }
    Ok(())
}
