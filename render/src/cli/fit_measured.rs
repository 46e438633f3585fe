//! `skin fit --spectrum` output for a fit with the instrument's geometry and a chosen model
//! (`--geometry sci` or `--model full|auto`): the free parameters, the surface term, the selection.

use super::fit::{FitArgs, colour_line, lab_json, params_json, skin_line, within_tolerance};
use multipole::fit::{FitOptions, MeasuredFit, MeasuredSpectrum};
use skin_optics::lab::Lab;
use std::path::Path;

/// Print `fit` (text or JSON, as `args` asks) and fail if it is beyond the tolerance.
pub(crate) fn report(
    args: &FitArgs,
    path: &Path,
    measured: &MeasuredSpectrum,
    fit: &MeasuredFit,
    opts: &FitOptions,
) -> anyhow::Result<()> {
    let lab =
        multipole::fit::ColourModel::new(opts.step_nm, opts.method, fit.skin)?.lab(&fit.skin)?;
    let hex = lab.to_srgb().to_hex();
    let free: Vec<&str> = fit.parameters.iter().map(|p| p.name()).collect();
    let values: serde_json::Map<String, serde_json::Value> = fit
        .parameters
        .iter()
        .map(|p| (p.name().to_string(), p.get(&fit.skin).into()))
        .collect();
    let steps: Vec<serde_json::Value> = fit
        .steps
        .iter()
        .map(|s| {
            serde_json::json!({
                "parameter": s.parameter.name(), "rms_before": s.rms_before,
                "rms_after": s.rms_after, "delta_criterion": s.delta_criterion,
                "accepted": s.accepted,
            })
        })
        .collect();
    let bounds: serde_json::Map<String, serde_json::Value> = fit
        .at_bounds()
        .iter()
        .map(|(p, b)| (p.name().to_string(), (*b).into()))
        .collect();
    if args.json {
        let out = serde_json::json!({
            "target": { "spectrum": path.display().to_string(), "points": measured.len() },
            "method": args.method.to_string(),
            "geometry": args.geometry.to_string(),
            "model": args.model.to_string(),
            "noise": args.noise,
            "parameters": params_json(&fit.skin),
            "free_parameters": values,
            "surface_reflectance": fit.surface_reflectance,
            "fitted": {
                "srgb": hex, "lab": lab_json(lab),
                "lambda_nm": measured.lambda_nm(), "reflectance": fit.model,
            },
            "residual": { "rms_reflectance": fit.rms, "seed_rms_reflectance": fit.seed_rms },
            "at_bounds": bounds,
            "criterion": fit.criterion,
            "selection": steps,
            "within_tolerance": fit.rms <= opts.max_rms,
        });
        println!("{out}");
    } else {
        print_text(args, path, measured, fit, lab, &hex, &free);
    }
    within_tolerance(path, fit.rms, opts.max_rms)
}

fn print_text(
    args: &FitArgs,
    path: &Path,
    measured: &MeasuredSpectrum,
    fit: &MeasuredFit,
    lab: Lab,
    hex: &str,
    free: &[&str],
) {
    let n = measured.len();
    println!(
        "{:<9}{} ({n} wavelengths, {}-{} nm, geometry {})",
        "target",
        path.display(),
        measured.lambda_nm()[0],
        measured.lambda_nm()[n - 1],
        args.geometry
    );
    println!("{}", skin_line(&fit.skin, args.method));
    let extra: Vec<String> = fit
        .parameters
        .iter()
        .skip(3)
        .map(|p| format!("{p} = {:.4}", p.get(&fit.skin)))
        .collect();
    if !extra.is_empty() {
        println!("{:<9}{}", "also", extra.join("  "));
    }
    println!("{}", colour_line("fitted", hex, lab));
    println!(
        "{:<9}RMS reflectance = {:.5} (seed model {:.5}); surface term {:.4}",
        "residual", fit.rms, fit.seed_rms, fit.surface_reflectance
    );
    println!(
        "{:<9}{} ({}): {}",
        "model",
        args.model,
        free.len(),
        free.join(", ")
    );
    let bounds: Vec<String> = fit
        .at_bounds()
        .iter()
        .map(|(p, b)| format!("{p} at {b}"))
        .collect();
    if !bounds.is_empty() {
        println!(
            "{:<9}on a bound of its fit range (the data wanted it further): {}",
            "bounds",
            bounds.join(", ")
        );
    }
    for s in &fit.steps {
        println!(
            "{:<9}{} {}: RMS {:.5} → {:.5}, Δcriterion {:+.1} at σ = {}",
            "",
            if s.accepted { "added" } else { "not added" },
            s.parameter,
            s.rms_before,
            s.rms_after,
            s.delta_criterion,
            args.noise
        );
    }
}
