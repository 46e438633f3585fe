//! Time versus error of every profile knob, against the converged reference (`skin::profile_error`).
//!
//! `cargo run --release -p multipole --features studies --example knob_errors [OUT.csv]` (default `out/multipole_knobs.csv`).
//! Columns: preset, lambda_nm, knob, value, time_us (median of 7 single-threaded runs),
//! max_energy_density_error, total_relative_error, r99_relative_error. One knob varies at a time,
//! the others stay at their defaults.

#[path = "shared/write.rs"]
mod shared;

use multipole::ProfileOptions;
use multipole::diffusion::slab::Poles;
use multipole::skin::{Method, profile, profile_error};
use skin_optics::{Preset, SkinParams, Wavelength};
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "out/multipole_knobs.csv".into());
    let d = ProfileOptions::default();
    // The same kind of sweep as `skin-validate`'s knob study (validation/src/compare/knobs.rs), on
    // purpose wider and timed: that study charts error against time for the documented ranges,
    // this example finds where each knob stops paying. An example cannot call the validation crate.
    type Set = fn(&mut ProfileOptions, usize);
    let counts: [(&str, &[usize], Set); 4] = [
        ("poles", &[0, 1, 2, 5, 10, 20, 50], |o, n| {
            o.diffusion.poles = Poles::Count(n)
        }),
        (
            "radial_samples",
            &[16, 32, 64, 128, 256, 512, 1024],
            |o, n| o.diffusion.radial_samples = n,
        ),
        ("transform_nodes", &[2, 3, 4, 5, 6, 8, 12], |o, n| {
            o.diffusion.transform_nodes = n
        }),
        (
            "transform_radii",
            &[8, 12, 16, 24, 32, 48, 64, 96, 128],
            |o, n| o.diffusion.transform_radii = n,
        ),
    ];
    let mut settings: Vec<(&str, String, ProfileOptions)> = Vec::new();
    for (knob, values, set) in counts {
        for &n in values {
            let mut o = d;
            set(&mut o, n);
            settings.push((knob, n.to_string(), o));
        }
        if knob == "poles" {
            settings.push(("poles", "exact".into(), d));
        }
    }
    for t in [1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-10, 1e-12] {
        let mut o = d;
        o.diffusion.transform_tolerance = t;
        settings.push(("transform_tolerance", format!("{t:e}"), o));
    }
    let mut csv = String::from(
        "preset,lambda_nm,knob,value,time_us,max_energy_density_error,total_relative_error,r99_relative_error\n",
    );
    let total = 3 * 2 * settings.len();
    let mut done = 0;
    for preset in [Preset::Light, Preset::Medium, Preset::Dark] {
        let skin = SkinParams::preset(preset);
        for nm in [450.0, 650.0] {
            let lambda = Wavelength::new(nm)?;
            for (knob, value, opts) in &settings {
                let mut times: Vec<f64> = (0..7)
                    .map(|_| {
                        let t = Instant::now();
                        let p = profile(&skin, lambda, Method::Multipole, opts);
                        std::hint::black_box(p).ok();
                        t.elapsed().as_secs_f64() * 1e6
                    })
                    .collect();
                times.sort_by(f64::total_cmp);
                let e = profile_error(&skin, lambda, Method::Multipole, opts)?;
                csv.push_str(&format!(
                    "{},{nm},{knob},{value},{:.1},{:.3e},{:.3e},{:.3e}\n",
                    preset.name(),
                    times[3],
                    e.max_energy_density_error,
                    e.total_relative_error,
                    e.r99_relative_error
                ));
                done += 1;
                eprint!("\r{done}/{total}");
            }
        }
    }
    eprintln!();
    shared::write_atomically(std::path::Path::new(&out), csv.as_bytes())?;
    Ok(())
}
