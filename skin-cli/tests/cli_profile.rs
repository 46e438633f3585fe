//! `skin profile` end to end: CSV shape and values, flag validation, the plot file.

use crate::common;

fn skin(args: &[&str]) -> std::process::Output {
    common::skin_cli("profile", args)
}

/// `skin profile` with the whitespace-separated `args`, which must succeed.
fn skin_ok(args: &str) -> std::process::Output {
    let out = skin(&args.split_whitespace().collect::<Vec<_>>());
    assert!(
        out.status.success(),
        "{args}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

#[test]
fn prints_csv_with_the_requested_samples() {
    let out =
        skin_ok("--melanin 0.002 --eumelanin 0.5 --hemoglobin 0.01 --lambda 550 --samples 64");
    let text = String::from_utf8(out.stdout).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("r_mm,reflectance_per_mm2"));
    let rows: Vec<(f64, f64)> = lines
        .map(|l| {
            let (a, b) = l.split_once(',').unwrap();
            (a.parse().unwrap(), b.parse().unwrap())
        })
        .collect();
    assert_eq!(rows.len(), 64);
    assert!((rows[0].0 - 0.001).abs() < 1e-9);
    assert!(rows.windows(2).all(|w| w[1].0 > w[0].0));
    assert!(rows.iter().all(|(_, v)| v.is_finite() && *v >= 0.0));
    // Same numbers as the library (the light preset is the Figure 1 set): the exact profile's Monte
    // Carlo shape has its own grid, which the CLI evaluates at the requested 64 geometric radii.
    let p = multipole::skin::profile(
        &skin_optics::SkinParams::preset(skin_optics::Preset::Light),
        skin_optics::Wavelength::new(550.0).unwrap(),
        multipole::Method::default(),
        &multipole::ProfileOptions::default(),
    )
    .unwrap();
    assert!((rows[63].0 - p.r_max_mm()).abs() <= 1e-6 * p.r_max_mm());
    for (r, v) in &rows {
        // r is printed to 7 digits: where R falls steeply that moves R(r) by up to ~1e-5, and the
        // last radius may round past the table's end (where eval is 0).
        let pv = p.eval(r.min(p.r_max_mm()));
        assert!(
            (v - pv).abs() <= 1e-4 * pv.max(1e-300),
            "r {r}: {v} vs {pv}"
        );
    }
    assert!(String::from_utf8_lossy(&out.stderr).contains("R_d = "));
}

/// `--surface oily` prints the total of adding-doubling under the oily lobe as the boundary
/// (docs/physics.md §10.1, through the library), and it differs from the smooth surface's.
#[test]
fn the_oily_surface_sets_the_exact_total() {
    let total = |out: std::process::Output| -> f64 {
        let err = String::from_utf8_lossy(&out.stderr).into_owned();
        let at = err.find("R_d = ").expect("an R_d line") + 6;
        err[at..]
            .split_whitespace()
            .next()
            .unwrap()
            .parse()
            .unwrap()
    };
    let oily = total(skin_ok(
        "--preset light --lambda 650 --samples 4 --surface oily --roughness 0.35",
    ));
    let smooth = total(skin_ok("--preset light --lambda 650 --samples 4"));
    let skin = skin_optics::SkinParams::preset(skin_optics::Preset::Light);
    let medium = multipole::LayeredMedium::skin(
        &skin,
        skin_optics::Wavelength::new(650.0).unwrap(),
        multipole::DEFAULT_G,
    )
    .unwrap()
    .with_surface(multipole::Surface::lobe(0.35, skin.oiliness()).unwrap());
    let want =
        multipole::skin::medium_total_reflectance(&medium, multipole::Method::Exact).unwrap();
    assert!((oily - want).abs() <= 1e-5, "{oily} vs {want}");
    assert!(oily - smooth > 0.005, "oily {oily}, smooth {smooth}");
}

#[test]
fn explicit_r_max_and_preset() {
    let out = skin_ok("--preset dark --lambda 650 --r-max 2 --samples 10");
    let text = String::from_utf8(out.stdout).unwrap();
    let last = text.lines().last().unwrap();
    let r: f64 = last.split_once(',').unwrap().0.parse().unwrap();
    assert!((r - 2.0).abs() < 1e-6);
}

#[test]
fn bad_values_name_the_flag_and_range() {
    for (args, flag, range) in [
        ("--lambda 100", "--lambda", "[250, 1000]"),
        ("--lambda 500 --samples 1", "--samples", "[2, 1000000]"),
        ("--lambda 500 --r-max -3", "--r-max", "[0.002, 10000]"),
        ("--lambda 500 --melanin 1.5", "--melanin", "[0, 1]"),
        ("--lambda 500 --method mcml", "--method", "multipole"),
        (
            "--lambda 500 --surface oily --roughness 0",
            "--roughness",
            "(0, 1]",
        ),
        ("--lambda 500 --surface rough", "--surface", "oily"),
    ] {
        let args: Vec<&str> = args.split_whitespace().collect();
        let out = skin(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(flag) && err.contains(range), "{args:?}: {err}");
    }
}

#[test]
fn plot_writes_a_png() {
    let dir = std::env::temp_dir().join(format!("skin-profile-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let png = dir.join("profile.png");
    skin_ok(&format!(
        "--lambda 550 --samples 32 --plot {}",
        png.display()
    ));
    let bytes = std::fs::read(&png).unwrap();
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn spectral_set_has_a_lambda_column_for_both_methods() {
    for method in ["exact", "multipole"] {
        let out = skin_ok(&format!(
            "--preset light --from 400 --to 700 --step 50 --samples 16 --method {method}"
        ));
        let text = String::from_utf8(out.stdout).unwrap();
        let mut lines = text.lines();
        assert_eq!(lines.next(), Some("lambda_nm,r_mm,reflectance_per_mm2"));
        let rows: Vec<Vec<f64>> = lines
            .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
            .collect();
        // 400, 450, …, 700: 7 wavelengths × 16 radii, in wavelength order.
        assert_eq!(rows.len(), 7 * 16);
        for (k, chunk) in rows.chunks(16).enumerate() {
            assert!(chunk.iter().all(|r| r[0] == 400.0 + 50.0 * k as f64));
            assert!(chunk.iter().all(|r| r[2].is_finite() && r[2] >= 0.0));
        }
    }
    // --lambda and --from exclude each other; --from needs --to.
    assert!(
        !skin(&[
            "--preset", "light", "--lambda", "550", "--from", "400", "--to", "500"
        ])
        .status
        .success()
    );
    assert!(
        !skin(&["--preset", "light", "--from", "400"])
            .status
            .success()
    );
    assert!(
        !skin(&["--preset", "light", "--from", "500", "--to", "400"])
            .status
            .success()
    );
}
