//! Times and accuracy of exact colour fits (BENCHMARKS.md `## Fit`): the two-stage default
//! (search at 8 quadrature points and 20 nm, corrected to the full model) and, with `--single`, a
//! single-stage fit with the full model throughout, on four skins from light to dark.
//!
//! `cargo run --release -p skin-fit --features studies --example fit_timing [-- --single]`; prints a Markdown table
//! (wall and process CPU seconds, evaluations, ΔE00, the fitted skin and the β_m range).

use skin_fit::{ColourModel, FitOptions, fit_colour};

/// Process CPU seconds (all threads).
fn cpu_s() -> f64 {
    cpu_time::ProcessTime::now().as_duration().as_secs_f64()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let two_stage = FitOptions::default();
    let single = FitOptions {
        search_quadrature_points: 24,
        ..FitOptions::default()
    };
    let model = ColourModel::new(two_stage.step_nm, two_stage.method, two_stage.base)?;
    let with_single = std::env::args().any(|a| a == "--single");
    println!(
        "| skin (C_m, β_m, C_h) | scheme | wall s | CPU s | evaluations (full) | ΔE00 | fitted | β_m range |"
    );
    println!("| --- | --- | --- | --- | --- | --- | --- | --- |");
    for p in [
        [0.002, 0.5, 0.01],
        [0.05, 0.6, 0.02],
        [0.25, 0.9, 0.04],
        [0.5, 0.9, 0.07],
    ] {
        let target = model.lab(&model.skin(p[0], p[1], p[2])?)?;
        let schemes: &[(&str, &FitOptions)] = if with_single {
            &[("two-stage", &two_stage), ("single-stage", &single)]
        } else {
            &[("two-stage", &two_stage)]
        };
        for (name, opts) in schemes {
            let (t, c) = (std::time::Instant::now(), cpu_s());
            let fit = fit_colour(target, opts)?;
            println!(
                "| {p:?} | {name} | {:.2} | {:.2} | {} ({}) | {:.1e} | ({:.4}, {:.3}, {:.4}) | {:?} |",
                t.elapsed().as_secs_f64(),
                cpu_s() - c,
                fit.evaluations,
                fit.full_evaluations,
                fit.delta_e,
                fit.skin.melanin(),
                fit.skin.eumelanin_blend(),
                fit.skin.hemoglobin(),
                fit.beta_range.map(|r| (r.min, r.max))
            );
        }
    }
    Ok(())
}
