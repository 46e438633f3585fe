//! `skin fit --geometry/--model` and `skin presets` end to end.

use multipole::Method;
use skin_fit::Geometry;
use skin_optics::Wavelength;
use skin_optics::measured::find_measured;
use std::process::{Command, Output};

fn skin(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_skin"))
        .args(args)
        .output()
        .expect("run skin")
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

#[test]
fn presets_lists_paper_measured_and_ita_skins() {
    let out = skin(&["presets"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let s = text(&out.stdout);
    for name in ["paper", "medium", "ca-forehead", "af-inner-arm", "ita-tan"] {
        assert!(
            s.lines().any(|l| l.starts_with(&format!("{name} "))),
            "{name} missing:\n{s}"
        );
    }
    // The paper's Figure 1 skin is L* ≈ 75 (grey plaster next to measured skin, L* 34–67).
    let paper = s.lines().find(|l| l.starts_with("paper ")).unwrap();
    assert!(paper.contains("ITA°"), "{paper}");
    // A measured preset is accepted where a preset is.
    let out = skin(&["spectrum", "--preset", "ita-tan", "--method", "multipole"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
}

/// An SCI spectrum of a measured preset's skin (blood near the surface, ρ_s, thickness), generated
/// by the multipole model and fitted by it with `--model full`. The refinement is local (from the
/// seed fit and three more starts), and in 11 dimensions it may stop short of the truth (RMS 0.0
/// there). The test pins what the fit does guarantee: it beats the seed model, stays within the
/// spectrum tolerance (0.02) and reports its geometry, model, free parameters and those on a bound.
#[test]
fn sci_full_fit_of_a_generated_spectrum_reports_its_model() {
    let preset = find_measured("ca-inner-arm").unwrap();
    let surface = Geometry::Sci
        .surface_reflectance(preset.skin.oiliness(), preset.skin.eta())
        .unwrap();
    let mut csv = String::from("lambda_nm,reflectance\n");
    for i in 0..31 {
        let nm = 400.0 + 10.0 * f64::from(i);
        let r = multipole::skin::diffuse_reflectance(
            &preset.skin,
            Wavelength::new(nm).unwrap(),
            Method::Multipole,
        )
        .unwrap();
        csv.push_str(&format!("{nm},{}\n", r + surface));
    }
    let path = std::env::temp_dir().join(format!("skin-cli-measured-{}.csv", std::process::id()));
    std::fs::write(&path, csv).unwrap();
    let p = path.to_str().unwrap();
    let fit = |model: &str, json: bool| {
        let mut a = vec![
            "fit",
            "--spectrum",
            p,
            "--geometry",
            "sci",
            "--model",
            model,
        ];
        a.extend(["--method", "multipole"]);
        if json {
            a.push("--json");
        }
        skin(&a)
    };
    let out = fit("full", true);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["geometry"], "sci");
    assert_eq!(v["model"], "full");
    let rms = v["residual"]["rms_reflectance"].as_f64().unwrap();
    let seed = v["residual"]["seed_rms_reflectance"].as_f64().unwrap();
    assert!(rms < seed && rms < 0.02, "{rms} vs seed {seed}");
    assert!(v["free_parameters"]["oiliness"].is_f64());
    assert!(v["free_parameters"]["epidermis_blood"].is_f64());
    // Parameters on a bound are reported, each one a free parameter within 0.1% of its range (no
    // range is wider than 2) of that end of it.
    let bounds = v["at_bounds"].as_object().unwrap();
    for (name, b) in bounds {
        let value = v["free_parameters"][name].as_f64().unwrap();
        assert!(
            (value - b.as_f64().unwrap()).abs() <= 2e-3,
            "{name}: {value} vs {b}"
        );
    }
    // Text output names the model and its parameters.
    let out = fit("auto", false);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let s = text(&out.stdout);
    assert!(s.contains("model    auto"), "{s}");
    assert!(s.contains("geometry sci"), "{s}");
    std::fs::remove_file(path).ok();
}

/// A colour target takes the instrument's geometry and the model, as a spectrum does, and comes
/// as sRGB or as CIELAB; bad CIELAB text is a usage error naming the coordinate and its range.
#[test]
fn colour_fits_take_a_lab_target_the_geometry_and_the_model() {
    for (lab, says) in [
        ("55,x,1", "a* 'x' is not a number"),
        ("101,0,0", "L* = 101 outside [0, 100]"),
        ("55,12", "2 comma-separated fields"),
    ] {
        let out = skin(&["fit", "--lab", lab]);
        assert_eq!(out.status.code(), Some(2), "{lab}");
        assert!(
            text(&out.stderr).contains(says),
            "{lab}: {}",
            text(&out.stderr)
        );
    }
    // A colour of the seed model's gamut under SCI: reached (the fit's ΔE00 is ~1e-6 for a colour
    // the model produces; 0.1 is a tenth of a just-noticeable difference).
    let out = skin(&[
        "fit",
        "--lab",
        "55,10,15",
        "--geometry",
        "sci",
        "--model",
        "full",
        "--method",
        "multipole",
        "--json",
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["geometry"], "sci");
    assert_eq!(v["free_parameters"].as_object().unwrap().len(), 11);
    assert!(v["residual"]["delta_e_2000"].as_f64().unwrap() < 0.1, "{v}");
    let out = skin(&["fit", "--srgb", "#b69a89", "--model", "tiny"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("valid: seed, full, auto"));
}
