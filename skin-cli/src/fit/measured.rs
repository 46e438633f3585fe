//! `skin fit` output for a fit with the instrument's geometry and a chosen model (`--geometry sci`
//! or `--model full|auto`), to a spectrum or a colour: the free parameters, the surface term, the
//! selection.

use super::{FitArgs, colour_line, lab_json, params_json, skin_line, within_tolerance};
use skin_fit::{
    FitOptions, MeasuredColourFit, MeasuredFit, MeasuredSpectrum, Parameter, SelectionStep,
};
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
    let lab = skin_fit::ColourModel::new(opts.step_nm, opts.method, fit.skin)?.lab(&fit.skin)?;
    let hex = lab.to_srgb().to_hex();
    let free: Vec<&str> = fit.parameters.iter().map(|p| p.name()).collect();
    let values = free_json(&fit.parameters, &fit.skin);
    let steps = steps_json(&fit.steps);
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
    print_skin(&fit.skin, &fit.parameters, args);
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
    print_steps(&fit.steps, "RMS", 5, args.noise);
}

/// The `skin` line and the free parameters beyond the seed's three (`also`).
fn print_skin(skin: &skin_optics::SkinParams, parameters: &[Parameter], args: &FitArgs) {
    println!("{}", skin_line(skin, args.method));
    let extra: Vec<String> = parameters
        .iter()
        .skip(3)
        .map(|p| format!("{p} = {:.4}", p.get(skin)))
        .collect();
    if !extra.is_empty() {
        println!("{:<9}{}", "also", extra.join("  "));
    }
}

fn free_json(
    parameters: &[Parameter],
    skin: &skin_optics::SkinParams,
) -> serde_json::Map<String, serde_json::Value> {
    parameters
        .iter()
        .map(|p| (p.name().to_string(), p.get(skin).into()))
        .collect()
}

fn steps_json(steps: &[SelectionStep]) -> Vec<serde_json::Value> {
    steps
        .iter()
        .map(|s| {
            serde_json::json!({
                "parameter": s.parameter.name(), "rms_before": s.rms_before,
                "rms_after": s.rms_after, "delta_criterion": s.delta_criterion,
                "accepted": s.accepted, "predicted": s.predicted,
            })
        })
        .collect()
}

/// The `auto` rounds, residuals in `unit` with `digits` decimals.
fn print_steps(steps: &[SelectionStep], unit: &str, digits: usize, noise: f64) {
    for s in steps {
        println!(
            "{:<9}{} {}: {unit} {:.digits$} → {:.digits$}{}, Δcriterion {:+.1} at σ = {noise}",
            "",
            if s.accepted { "added" } else { "not added" },
            s.parameter,
            s.rms_before,
            s.rms_after,
            if s.predicted { " (score test)" } else { "" },
            s.delta_criterion,
        );
    }
}

/// Print a colour fit with the instrument's geometry and a chosen model (text or JSON) and fail
/// when it is beyond the gamut threshold.
pub(crate) fn report_colour(
    args: &FitArgs,
    target_hex: &str,
    fit: &MeasuredColourFit,
    opts: &FitOptions,
) -> anyhow::Result<()> {
    let hex = fit.lab.to_srgb().to_hex();
    let free: Vec<&str> = fit.parameters.iter().map(|p| p.name()).collect();
    if args.json {
        let out = serde_json::json!({
            "target": { "srgb": target_hex, "lab": lab_json(fit.target) },
            "method": args.method.to_string(),
            "geometry": args.geometry.to_string(),
            "model": args.model.to_string(),
            "noise": args.noise,
            "noise_delta_e_2000": fit.noise_delta_e,
            "parameters": params_json(&fit.skin),
            "free_parameters": free_json(&fit.parameters, &fit.skin),
            "fitted": { "srgb": hex, "lab": lab_json(fit.lab) },
            "residual": { "delta_e_2000": fit.delta_e, "seed_delta_e_2000": fit.seed_delta_e },
            "selection": steps_json(&fit.steps),
            "in_gamut": fit.delta_e <= opts.gamut_threshold_de,
        });
        println!("{out}");
    } else {
        println!(
            "{} (geometry {})",
            colour_line("target", target_hex, fit.target),
            args.geometry
        );
        print_skin(&fit.skin, &fit.parameters, args);
        println!("{}", colour_line("fitted", &hex, fit.lab));
        println!(
            "{:<9}ΔE2000 = {:.3} (seed model {:.3}); colour noise σ_c = {:.3} ΔE2000 per coordinate from σ = {}",
            "residual", fit.delta_e, fit.seed_delta_e, fit.noise_delta_e, args.noise
        );
        let note = if free.len() > 3 {
            " (more free parameters than the colour's three coordinates: their values are not determined)"
        } else {
            ""
        };
        println!(
            "{:<9}{} ({}): {}{note}",
            "model",
            args.model,
            free.len(),
            free.join(", ")
        );
        print_steps(&fit.steps, "ΔE2000", 3, args.noise);
    }
    if fit.delta_e > opts.gamut_threshold_de {
        anyhow::bail!(
            "{target_hex} is out of gamut: the nearest skin (above) is ΔE2000 {:.1} away (threshold {})",
            fit.delta_e,
            opts.gamut_threshold_de
        );
    }
    Ok(())
}
