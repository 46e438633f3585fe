//! Error and cost of the exact profile read from the shape table (`multipole::skin::ShapeTable`)
//! against an independent layered Monte Carlo run (seed 7, 0.02 mm annuli to 6 mm), energy-weighted
//! (`validation::shape_error`), for the light, medium and dark presets at 450, 550 and 650 nm.
//!
//! `cargo run --release -p validation --example table_profiles [TABLE_PHOTONS [DEPTHS_PER_OCTAVE
//! [RADIAL_PER_DECADE [PATH_PER_DECADE [MC_PHOTONS]]]]]` (defaults: the table defaults, 10⁶).

use multipole::montecarlo::{DEFAULT_SKIN_G, LayerStack, McOptions, RadialGrid, run};
use multipole::skin::{Method, ShapeTable, ShapeTableOptions, table_profile, total_reflectance};
use skin_optics::{Preset, SkinParams, Wavelength};
use std::time::Instant;
use validation::shape_error::energy_error;

fn main() -> anyhow::Result<()> {
    let args: Vec<u64> = std::env::args()
        .skip(1)
        .map(|s| s.parse())
        .collect::<Result<_, _>>()?;
    let d = ShapeTableOptions::default();
    let arg = |i: usize, v: u64| args.get(i).copied().unwrap_or(v);
    let opts = ShapeTableOptions {
        photons: arg(0, d.photons),
        depths_per_octave: arg(1, d.depths_per_octave.into()).try_into()?,
        radial_per_decade: arg(2, d.radial_per_decade.into()).try_into()?,
        path_per_decade: arg(3, d.path_per_decade.into()).try_into()?,
        ..d
    };
    let mc_photons = arg(4, 1_000_000);
    let t0 = Instant::now();
    let table = ShapeTable::build(DEFAULT_SKIN_G, 1.4, &opts, rayon::current_num_threads(), |_| {})?;
    println!("{opts:?}: built in {:.1} s wall", t0.elapsed().as_secs_f64());
    println!("| preset | λ (nm) | error | MC noise | eval (ms) |");
    println!("| --- | --- | --- | --- | --- |");
    let grid = RadialGrid::new(0.02, 300)?;
    for preset in [Preset::Light, Preset::Medium, Preset::Dark] {
        for nm in [450.0, 550.0, 650.0] {
            let skin = SkinParams::preset(preset);
            let lambda = Wavelength::new(nm)?;
            let total = total_reflectance(&skin, lambda, Method::Exact)?;
            let c = skin.coefficients(lambda);
            let s = c.epidermis.sigma_s_prime / (1.0 - DEFAULT_SKIN_G);
            let t = Instant::now();
            let p = table
                .profile(s, c.epidermis.sigma_a, c.dermis.sigma_a, skin.epidermis_thickness_mm(), total)?
                .ok_or_else(|| anyhow::anyhow!("{preset:?} {nm} nm outside the table"))?;
            let ms = t.elapsed().as_secs_f64() * 1e3;
            let stack = LayerStack::skin(&skin, lambda, DEFAULT_SKIN_G)?;
            let mc = run(&stack, &McOptions::new(mc_photons, 32, 7)?.with_grid(grid));
            let (err, noise) = energy_error(&p, &mc);
            println!(
                "| {} | {nm} | {:.2}% | {:.2}% | {ms:.2} |",
                preset.name(),
                100.0 * err,
                100.0 * noise
            );
        }
    }
    let _ = table_profile;
    Ok(())
}
