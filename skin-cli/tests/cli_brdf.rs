//! `skin brdf`: CSV shape and values (against brdf's quadrature and the smooth-surface limit),
//! flag validation (one line naming the flag and range, exit code 2), and the PNG chart.

use crate::common;

use brdf::TorranceSparrow;
use brdf::fresnel::dielectric_reflectance;
use std::process::Output;

fn skin(args: &[&str]) -> Output {
    common::skin_cli("brdf", args)
}

/// Parse the CSV, checking the header and the 0–89° rows.
fn parse(out: &Output) -> Vec<(f64, f64)> {
    assert!(
        out.status.success(),
        "stderr: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout.clone()).expect("UTF-8 CSV");
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("theta_deg,albedo"));
    let rows: Vec<(f64, f64)> = lines
        .map(|l| {
            let (t, a) = l.split_once(',').expect("two columns");
            (t.parse().expect("theta"), a.parse().expect("albedo"))
        })
        .collect();
    assert_eq!(rows.len(), 90);
    for (i, &(t, a)) in rows.iter().enumerate() {
        assert_eq!(t, i as f64);
        assert!((0.0..=1.0).contains(&a), "albedo {a} at {t}°");
    }
    rows
}

#[test]
fn defaults_match_the_library_quadrature() {
    let rows = parse(&skin(&[]));
    let ts = TorranceSparrow::new(0.3, 0.25, 1.4).expect("valid");
    for &(t, a) in &rows {
        let expected = ts
            .directional_albedo_quadrature(t.to_radians().cos(), 512)
            .expect("valid");
        // 6 printed decimals; the CLI's 96-node rule is within 1.1e-5 of the reference.
        assert!((a - expected).abs() < 2e-5, "{t}°: {a} vs {expected}");
    }
    // At normal incidence a rough lobe reflects ≈ ρ_s F(0), F(0) = ((1.4 − 1)/(1.4 + 1))² = 0.027 778:
    // the microfacets tilt by ~atan(m) = 17° at m = 0.3, where F is 0.4% above F(0), and masking
    // removes a little, so the albedo sits within 1% of ρ_s F(0) (measured +0.2%).
    let fresnel_0 = (0.4f64 / 2.4).powi(2);
    assert!(
        (rows[0].1 - 0.25 * fresnel_0).abs() < 0.01 * 0.25 * fresnel_0,
        "{}",
        rows[0].1
    );
}

#[test]
fn smooth_oily_surface_reflects_fresnel() {
    let rows = parse(&skin(&[
        "--roughness",
        "0.01",
        "--oil",
        "1",
        "--eta",
        "1.4",
    ]));
    for &(t, a) in rows.iter().filter(|(t, _)| *t <= 80.0) {
        let f = dielectric_reflectance(t.to_radians().cos(), 1.4);
        assert!((a - f).abs() < 5e-4, "{t}°: {a} vs F = {f}");
    }
}

#[test]
fn bad_values_name_the_flag_and_range() {
    for (args, needle) in [
        (vec!["--roughness", "0"], "(0, 1]"),
        (vec!["--roughness", "1.5"], "(0, 1]"),
        (vec!["--roughness", "NaN"], "(0, 1]"),
        (vec!["--oil", "-0.5"], "[0, 1]"),
        (vec!["--oil", "abc"], "not a number"),
        (vec!["--eta", "5"], "[1, 3]"),
    ] {
        let out = skin(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        assert!(out.stdout.is_empty(), "{args:?}: no partial CSV");
        let err = String::from_utf8_lossy(&out.stderr);
        let first = err.lines().next().unwrap_or_default();
        assert!(first.contains(args[0]), "{args:?}: {first}");
        assert!(first.contains(needle), "{args:?}: {first}");
    }
}

#[test]
fn plot_writes_a_png() {
    let dir = std::env::temp_dir().join(format!("skin-cli-brdf-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let png = dir.join("albedo.png");
    let out = skin(&["--plot", png.to_str().expect("UTF-8 path")]);
    parse(&out);
    let bytes = std::fs::read(&png).expect("chart written");
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
    std::fs::remove_dir_all(&dir).ok();
}
