//! `skin spectrum` end to end: the built binary, its CSV, its errors and its chart.

use crate::common;

use common::{stderr, stdout};
use std::path::PathBuf;
use std::process::Output;

fn skin(args: &[&str]) -> Output {
    common::skin_cli("spectrum", args)
}

const HEADER: &str = "lambda_nm,sigma_a_epidermis_per_mm,sigma_a_dermis_per_mm,sigma_s_reduced_per_mm,diffuse_reflectance";

#[test]
fn defaults_print_header_and_31_rows() {
    let o = skin(&[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], HEADER);
    assert_eq!(lines.len(), 1 + 31);
    assert!(lines[1].starts_with("400,"));
    assert!(lines[31].starts_with("700,"));
    for line in &lines[1..] {
        let v: Vec<f64> = line.split(',').map(|f| f.parse().unwrap()).collect();
        assert_eq!(v.len(), 5);
        assert!(v[1..4].iter().all(|x| x.is_finite() && *x > 0.0), "{line}");
        assert!(v[4] > 0.0 && v[4] < 1.0, "{line}");
    }
    // The colour of the reflectance goes to stderr as one `srgb #rrggbb` line.
    let err = stderr(&o);
    let srgb = err
        .lines()
        .find(|l| l.starts_with("srgb #"))
        .expect("srgb line");
    assert_eq!(srgb.len(), "srgb #c8967d".len());
}

#[test]
fn explicit_fractions_and_grid_are_honoured() {
    let o = skin(&[
        "--melanin",
        "0.3",
        "--eumelanin",
        "0.9",
        "--hemoglobin",
        "0.04",
        "--from",
        "500",
        "--to",
        "600",
        "--step",
        "25",
        "--method",
        "multipole",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    let nms: Vec<&str> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').next().unwrap())
        .collect();
    assert_eq!(nms, ["500", "525", "550", "575", "600"]);
    // σa_epi at 500 nm for C_m = 0.3, β_m = 0.9 (eq. 1 with eqs 2–4 by hand): 0.3·(0.9·67.9163 + 0.1·43.8824) + 0.7·0.070222.
    let epi: f64 = text
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .nth(1)
        .unwrap()
        .parse()
        .unwrap();
    let expect = 0.3 * (0.9 * 67.916_269 + 0.1 * 43.882_411) + 0.7 * 0.070_221_73;
    assert!((epi - expect).abs() < 1e-5, "{epi} vs {expect}");
}

#[test]
fn preset_dark_is_darker_than_light() {
    let mean_r = |preset: &str| {
        let o = skin(&["--preset", preset]);
        assert!(o.status.success(), "{}", stderr(&o));
        let t = stdout(&o);
        let r: Vec<f64> = t
            .lines()
            .skip(1)
            .map(|l| l.rsplit(',').next().unwrap().parse().unwrap())
            .collect();
        r.iter().sum::<f64>() / r.len() as f64
    };
    assert!(mean_r("dark") < 0.5 * mean_r("light"));
}

#[test]
fn bad_values_exit_nonzero_naming_the_flag() {
    let cases: [(&[&str], &str, &str); 8] = [
        (&["--melanin", "1.5"], "--melanin", "[0, 1]"),
        (&["--melanin", "nan"], "--melanin", "[0, 1]"),
        (&["--hemoglobin=-0.1"], "--hemoglobin", "[0, 1]"),
        (&["--step", "0"], "--step", "[0.01, 750] nm"),
        (&["--step", "-5"], "--step", "[0.01, 750] nm"),
        (&["--from", "100"], "--from", "[250, 1000] nm"),
        (&["--to", "1200"], "--to", "[250, 1000] nm"),
        (&["--from", "700", "--to", "400"], "--to", "[250, 1000] nm"),
    ];
    for (args, flag, range) in cases {
        let o = skin(args);
        assert!(!o.status.success(), "{args:?} succeeded");
        assert!(o.stdout.is_empty(), "{args:?} printed CSV");
        let err = stderr(&o);
        let first = err.lines().next().unwrap_or_default();
        assert!(
            first.contains(flag) && first.contains(range),
            "{args:?}: {first}"
        );
    }
    let o = skin(&["--method", "guess"]);
    assert!(!o.status.success());
    assert!(stderr(&o).lines().next().unwrap().contains("--method"));
}

#[test]
fn plot_is_written_atomically() {
    let dir = std::env::temp_dir().join(format!("skin-cli-spectrum-{}", std::process::id()));
    let path: PathBuf = dir.join("sub").join("spectrum.png");
    let o = skin(&["--preset", "medium", "--plot", path.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let img = image::open(&path).expect("a PNG").to_rgb8();
    assert_eq!(img.dimensions(), (1000, 1100));
    assert!(img.pixels().filter(|p| p.0 != [255, 255, 255]).count() > 10_000);
    let leftovers: Vec<_> = std::fs::read_dir(path.parent().unwrap())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .filter(|n| n.to_string_lossy().ends_with(".tmp"))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn both_methods_give_physical_reflectance() {
    let last_column = |method: &str| -> Vec<f64> {
        let o = skin(&["--method", method, "--step", "50"]);
        assert!(o.status.success(), "{}", stderr(&o));
        stdout(&o)
            .lines()
            .skip(1)
            .map(|l| l.rsplit(',').next().unwrap().parse().unwrap())
            .collect()
    };
    let multipole = last_column("multipole");
    let exact = last_column("exact");
    assert_eq!(multipole.len(), 7);
    for (m, e) in multipole.iter().zip(&exact) {
        assert!(*m > 0.0 && *m < 1.0 && *e > 0.0 && *e < 1.0);
    }
    // The default is exact transport ([exact]); the paper's multipole stays selectable.
    let default: Vec<f64> = stdout(&skin(&["--step", "50"]))
        .lines()
        .skip(1)
        .map(|l| l.rsplit(',').next().unwrap().parse().unwrap())
        .collect();
    assert_eq!(default, exact);
}
