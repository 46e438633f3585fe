//! Error against cost of every knob of the exact profile's shape table
//! (`multipole::skin::ShapeTable`): each knob varied alone from the defaults, the energy-weighted
//! error (`validation::shape_error`) against independent layered Monte Carlo runs (seed 7, 0.02 mm
//! annuli to 6 mm) of the light, medium and dark presets at 450, 550 and 650 nm, the table's build
//! time (CPU-s of the whole process while building) and one profile's evaluation time (wall, one
//! thread, median of 9 cases).
//!
//! `cargo run --release -p validation --example table_profiles [MC_PHOTONS [OUT.csv]]`
//! (default 10⁶ photons per reference, `out/table_knobs.csv`).

use multipole::montecarlo::{DEFAULT_G, LayeredMedium, McOptions, McResult, RadialGrid, run};
use multipole::skin::{Method, ShapeTable, ShapeTableOptions, total_reflectance};
use skin_optics::{Preset, SkinParams, Wavelength};
use std::io::Write;
use std::time::Instant;
use validation::shape_error::energy_error;

/// This process's user + system CPU time, seconds (Linux `/proc/self/stat`, 100 ticks per second).
fn process_cpu_s() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after = stat.rsplit(')').next().unwrap_or("");
    let f: Vec<f64> = after
        .split_whitespace()
        .skip(11)
        .take(2)
        .filter_map(|v| v.parse().ok())
        .collect();
    f.iter().sum::<f64>() / 100.0
}

struct Case {
    name: String,
    sigma_s: f64,
    sigma_a: (f64, f64),
    d_mm: f64,
    total: f64,
    mc: McResult,
}

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let mc_photons: u64 = args
        .next()
        .map(|s| s.parse())
        .transpose()?
        .unwrap_or(1_000_000);
    let out = args.next().unwrap_or_else(|| "out/table_knobs.csv".into());
    let grid = RadialGrid::new(0.02, 300)?;
    let mut cases = Vec::new();
    for preset in [Preset::Light, Preset::Medium, Preset::Dark] {
        for nm in [450.0, 550.0, 650.0] {
            let skin = SkinParams::preset(preset);
            let lambda = Wavelength::new(nm)?;
            let c = skin.coefficients(lambda);
            let stack = LayeredMedium::skin(&skin, lambda, DEFAULT_G)?;
            let mc = run(&stack, &McOptions::new(mc_photons, 32, 7)?.with_grid(grid));
            cases.push(Case {
                name: format!("{} {nm}", preset.name()),
                sigma_s: c.epidermis.sigma_s_prime / (1.0 - DEFAULT_G),
                sigma_a: (c.epidermis.sigma_a, c.dermis.sigma_a),
                d_mm: skin.epidermis_thickness_mm(),
                total: total_reflectance(&skin, lambda, Method::Exact)?,
                mc,
            });
            eprintln!("reference {} done", cases.last().map_or("", |c| &c.name));
        }
    }
    let d = ShapeTableOptions::default();
    let mut settings = vec![("default", d)];
    for photons in [50_000, 200_000, 1_000_000] {
        settings.push(("photons", ShapeTableOptions { photons, ..d }));
    }
    for depths_per_octave in [1, 2] {
        settings.push((
            "depths_per_octave",
            ShapeTableOptions {
                depths_per_octave,
                ..d
            },
        ));
    }
    for radial_per_decade in [8, 32] {
        settings.push((
            "radial_per_decade",
            ShapeTableOptions {
                radial_per_decade,
                ..d
            },
        ));
    }
    for path_per_decade in [4, 16] {
        settings.push((
            "path_per_decade",
            ShapeTableOptions {
                path_per_decade,
                ..d
            },
        ));
    }
    if let Some(dir) = std::path::Path::new(&out).parent() {
        std::fs::create_dir_all(dir)?;
    }
    let mut csv = std::fs::File::create(&out)?;
    write!(
        csv,
        "knob,photons,depths_per_octave,radial_per_decade,path_per_decade,build_cpu_s,eval_ms"
    )?;
    for c in &cases {
        write!(csv, ",{}", c.name.replace(' ', "_"))?;
    }
    writeln!(csv, ",worst")?;
    println!(
        "| knob | photons | depths/oct | radial/dec | path/dec | build CPU-s | eval ms | {} | worst |",
        cases
            .iter()
            .map(|c| c.name.as_str())
            .collect::<Vec<_>>()
            .join(" | ")
    );
    println!("|{}", " --- |".repeat(8 + cases.len()));
    for (knob, o) in settings {
        let cpu0 = process_cpu_s();
        let table = ShapeTable::build(DEFAULT_G, 1.4, &o, rayon::current_num_threads(), |_| {})?;
        let build = process_cpu_s() - cpu0;
        let mut times = Vec::new();
        let mut errs = Vec::new();
        for c in &cases {
            let t = Instant::now();
            let p = table
                .profile(c.sigma_s, c.sigma_a.0, c.sigma_a.1, c.d_mm, c.total)?
                .ok_or_else(|| anyhow::anyhow!("{} outside the table", c.name))?;
            times.push(t.elapsed().as_secs_f64() * 1e3);
            errs.push(energy_error(&p, &c.mc).0);
        }
        times.sort_by(f64::total_cmp);
        let eval = times[times.len() / 2];
        let worst = errs.iter().copied().fold(0.0, f64::max);
        write!(
            csv,
            "{knob},{},{},{},{},{build:.2},{eval:.3}",
            o.photons, o.depths_per_octave, o.radial_per_decade, o.path_per_decade
        )?;
        for e in &errs {
            write!(csv, ",{e:.5}")?;
        }
        writeln!(csv, ",{worst:.5}")?;
        println!(
            "| {knob} | {} | {} | {} | {} | {build:.1} | {eval:.2} | {} | {:.2}% |",
            o.photons,
            o.depths_per_octave,
            o.radial_per_decade,
            o.path_per_decade,
            errs.iter()
                .map(|e| format!("{:.2}%", 100.0 * e))
                .collect::<Vec<_>>()
                .join(" | "),
            100.0 * worst
        );
    }
    let noise: Vec<String> = cases
        .iter()
        .map(|c| format!("{}: {:.2}%", c.name, 100.0 * energy_error_noise(&c.mc)))
        .collect();
    println!(
        "reference noise (expected error of a perfect model): {}",
        noise.join(", ")
    );
    Ok(())
}

/// Expected energy-weighted error of a model equal to the truth against `mc` (its noise alone).
fn energy_error_noise(mc: &McResult) -> f64 {
    let g = mc.radial.grid;
    (0..g.bins())
        .map(|i| (2.0 / std::f64::consts::PI).sqrt() * mc.radial.stderr[i] * g.annulus_area_mm2(i))
        .sum::<f64>()
        / mc.diffuse_reflectance.mean
}
