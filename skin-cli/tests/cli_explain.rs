//! `skin render --explain` and the multipole warning, end to end.

use render::testing::LIGHT_SLAB as SLAB;

/// `skin render --explain` prints one block per skin material with every choice, and
/// `--method multipole` warns once where diffusion is off (the light preset: +4.3% at 400 nm,
/// BENCHMARKS.md), naming the wavelengths (from the blue end).
#[test]
fn explain_prints_the_choices_and_multipole_warns() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("slab.toml");
    std::fs::write(&scene, SLAB).unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_skin"))
        .args(["render", "--scene"])
        .arg(&scene)
        .args(["--out"])
        .arg(dir.path().join("out"))
        .args([
            "--width",
            "4",
            "--height",
            "4",
            "--spp",
            "1",
            "--quiet",
            "--explain",
            "--method",
            "multipole",
            "--no-cache",
        ])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    for row in [
        "skin material 'skin'",
        "wavelengths",
        "profile extent",
        "table size",
        "shapes",
        "shape photons",
        "level of detail",
        "transport",
        "cache            off",
    ] {
        assert!(stdout.contains(row), "no '{row}' in\n{stdout}");
    }
    assert_eq!(
        stderr.matches("warning: --method multipole").count(),
        1,
        "{stderr}"
    );
    assert!(
        stderr.contains("'skin' at 3") && stderr.contains(" nm"),
        "{stderr}"
    );
}
