//! `skin fit` end to end: colour and spectrum fits, JSON output, out-of-gamut reporting, bad input.

use crate::common;

use common::stderr;
use multipole::Method;
use skin_fit::{ColourModel, FitOptions};
use skin_optics::Wavelength;
use skin_optics::lab::Lab;
use std::path::PathBuf;
use std::process::Output;

fn skin_fit(args: &[&str]) -> Output {
    common::skin_cli("fit", args)
}

/// A CSV file in the temp directory, unique per test.
fn temp_csv(name: &str, body: &str) -> PathBuf {
    let path = std::env::temp_dir().join(format!("skin-cli-fit-{}-{name}.csv", std::process::id()));
    std::fs::write(&path, body).unwrap();
    path
}

fn json(out: &Output) -> serde_json::Value {
    assert!(out.status.success(), "{}", stderr(out));
    serde_json::from_slice(&out.stdout).expect("stdout is one JSON object")
}

#[test]
fn colour_of_a_model_skin_fits_back_within_half_a_delta_e() {
    // The default forward model is exact (recorded in the JSON); `--method multipole` fits with the
    // paper's diffusion. Each fits a colour it generated.
    for (args, method) in [
        (&[][..], Method::Exact),
        (&["--method", "multipole"][..], Method::Multipole),
    ] {
        let model = model_of(method);
        let xyz = model.xyz(&model.skin(0.05, 0.6, 0.02).unwrap()).unwrap();
        let hex = model_hex(method, [0.05, 0.6, 0.02]);
        let mut all = vec!["--srgb", &hex, "--json"];
        all.extend_from_slice(args);
        let v = json(&skin_fit(&all));
        assert_eq!(v["method"], method.to_string().as_str(), "{v}");
        assert_eq!(v["target"]["srgb"], hex.as_str());
        assert_eq!(v["in_gamut"], true);
        // The 8-bit hex itself is up to ~0.3 ΔE00 from the model colour; the fit must reach the hex.
        assert!(v["residual"]["delta_e_2000"].as_f64().unwrap() < 0.5, "{v}");
        let p = &v["parameters"];
        assert!((p["melanin"].as_f64().unwrap() - 0.05).abs() < 0.01, "{v}");
        let ita = v["fitted"]["lab"]["ita_deg"].as_f64().unwrap();
        let lab = Lab::from_xyz(xyz);
        assert!(
            (ita - lab.ita_deg()).abs() < 1.0,
            "{method}: {ita} vs {}",
            lab.ita_deg()
        );
        assert_eq!(
            v["fitted"]["lab"]["ita_category"],
            lab.ita_category().name()
        );
        // The two-stage exact fit reports its full-model evaluations; the multipole fit has none.
        let full = v["full_evaluations"].as_u64().unwrap();
        assert_eq!(full > 0, method == Method::Exact, "{v}");
    }
}

/// The fit's colour model for `method` at the default options.
fn model_of(method: Method) -> ColourModel {
    let opts = FitOptions::default();
    ColourModel::new(opts.step_nm, method, opts.base).unwrap()
}

/// The hex colour of a model skin (C_m, β_m, C_h), so the target is inside the model's gamut.
fn model_hex(method: Method, p: [f64; 3]) -> String {
    let model = model_of(method);
    let xyz = model.xyz(&model.skin(p[0], p[1], p[2]).unwrap()).unwrap();
    xyz.to_linear_srgb().to_srgb().to_hex()
}

#[test]
fn text_output_names_parameters_colour_residual_and_ita() {
    let hex = model_hex(Method::Exact, [0.02, 0.5, 0.01]);
    let out = skin_fit(&["--srgb", &hex]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8(out.stdout).unwrap();
    let target = format!("target   {hex}");
    for needle in [
        &target[..],
        "C_m = ",
        "β_m = ",
        "C_h = ",
        "fitted   #",
        "ΔE2000 = ",
        "ITA° ",
        "L*a*b* (",
        "(method exact)",
    ] {
        assert!(text.contains(needle), "missing {needle:?} in\n{text}");
    }
}

#[test]
fn pure_green_is_reported_out_of_gamut_with_the_nearest_skin() {
    let out = skin_fit(&["--srgb", "#00ff00", "--json"]);
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(
        err.contains("out of gamut") && err.contains("#00ff00"),
        "{err}"
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["in_gamut"], false);
    assert!(v["residual"]["delta_e_2000"].as_f64().unwrap() > 3.0);
    assert!(v["parameters"]["melanin"].is_number());
}

#[test]
fn spectrum_of_known_skin_fits_back() {
    for method in [Method::Exact, Method::Multipole] {
        spectrum_round_trip(method);
    }
}

fn spectrum_round_trip(method: Method) {
    let truth = (0.1, 0.7, 0.03);
    let skin = skin_optics::SkinParams::new(truth.0, truth.1, truth.2, 0.25).unwrap();
    let mut csv = String::from("# model skin C_m 0.1, β_m 0.7, C_h 0.03\nlambda_nm,reflectance\n");
    for i in 0..31 {
        let nm = 400.0 + 10.0 * f64::from(i);
        let r = multipole::skin::diffuse_reflectance(&skin, Wavelength::new(nm).unwrap(), method)
            .unwrap();
        csv.push_str(&format!("{nm},{r}\n"));
    }
    let path = temp_csv(&format!("known-{method}"), &csv);
    let name = method.to_string();
    let v = json(&skin_fit(&[
        "--spectrum",
        path.to_str().unwrap(),
        "--json",
        "--method",
        &name,
    ]));
    std::fs::remove_file(&path).ok();
    assert_eq!(v["method"], name.as_str());
    assert!(
        v["residual"]["rms_reflectance"].as_f64().unwrap() < 1e-3,
        "{v}"
    );
    let p = &v["parameters"];
    assert!(
        (p["melanin"].as_f64().unwrap() / truth.0 - 1.0).abs() < 0.02,
        "{v}"
    );
    assert!(
        (p["eumelanin_blend"].as_f64().unwrap() - truth.1).abs() < 0.02,
        "{v}"
    );
    assert!(
        (p["hemoglobin"].as_f64().unwrap() / truth.2 - 1.0).abs() < 0.05,
        "{v}"
    );
    assert_eq!(v["fitted"]["reflectance"].as_array().unwrap().len(), 31);
}

#[test]
fn bad_spectra_each_give_one_line_naming_the_line() {
    let header = "lambda_nm,reflectance\n";
    let cases = [
        (
            "number",
            format!("{header}400,0.2\n410,zero\n420,0.3\n"),
            "line 3: reflectance `zero` is not a finite number",
        ),
        (
            "order",
            format!("{header}400,0.2\n420,0.3\n410,0.3\n"),
            "line 4: wavelength 410 nm does not increase",
        ),
        (
            "range",
            format!("{header}400,0.2\n410,1.5\n420,0.3\n"),
            "line 3: reflectance = 1.5 outside [0, 1]",
        ),
        (
            "lambda",
            format!("{header}400,0.2\n410,0.3\n750,0.3\n"),
            "line 4: lambda_nm = 750 outside [400, 700] nm",
        ),
        (
            "header",
            "400,0.2\n410,0.3\n420,0.3\n".to_string(),
            "line 1: expected the header",
        ),
        (
            "fields",
            format!("{header}400,0.2\n410\n420,0.3\n"),
            "line 3: 1 fields, expected 2",
        ),
    ];
    for (name, body, want) in cases {
        let path = temp_csv(name, &body);
        let out = skin_fit(&["--spectrum", path.to_str().unwrap()]);
        std::fs::remove_file(&path).ok();
        assert_eq!(out.status.code(), Some(1), "{name}");
        let err = stderr(&out);
        assert_eq!(err.trim().lines().count(), 1, "{name}: {err}");
        assert!(err.contains(want), "{name}: {err}");
    }
    let out = skin_fit(&["--spectrum", "/nonexistent/skin.csv"]);
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert!(
        err.contains("spectrum file /nonexistent/skin.csv cannot be read"),
        "{err}"
    );
    // The OS error is printed once, not once by the message and again as its source.
    assert_eq!(err.matches("os error").count(), 1, "{err}");
}

#[test]
fn bad_usage_exits_with_code_2() {
    for args in [
        &["--srgb", "#12345"][..],
        &["--srgb", "skin"][..],
        &[][..],
        &["--srgb", "#b69a89", "--spectrum", "x.csv"][..],
        &["--srgb", "#b69a89", "--method", "magic"][..],
        &["--srgb", "#b69a89", "--step-nm", "0"][..],
    ] {
        let out = skin_fit(args);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        assert!(
            stderr(&out).starts_with("error:"),
            "{args:?}: {}",
            stderr(&out)
        );
    }
    let out = skin_fit(&["--srgb", "#12345"]);
    assert!(
        stderr(&out).contains("not an sRGB colour"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn skin_spectrum_reports_lab_and_ita_on_stderr() {
    let out = common::skin_cli("spectrum", &["--preset", "medium", "--method", "multipole"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let err = stderr(&out);
    let line = err
        .lines()
        .find(|l| l.starts_with("lab L*="))
        .expect("lab line");
    // Same numbers as the fit's colour model at the same grid (400-700 nm every 10 nm).
    let opts = FitOptions::default();
    let model = ColourModel::new(10.0, Method::Multipole, opts.base).unwrap();
    let lab = model
        .lab(&skin_optics::SkinParams::preset(
            skin_optics::Preset::Medium,
        ))
        .unwrap();
    assert_eq!(line, skin_cli::spectrum::lab_line(&lab));
}

#[test]
fn help_names_the_exact_default_and_the_multipole_alternative() {
    let out = skin_fit(&["--help"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("[default: exact]"), "{text}");
    assert!(text.contains("multipole"), "{text}");
}
