//! `skin-validate mc` at the documented maximum of 1e6 batches runs within a 2 GiB address space
//! (`ulimit -v`): the batch tallies are folded as they finish instead of being held all at once.

use std::process::Command;

#[test]
fn mc_with_a_million_batches_runs_within_2_gib() {
    let out = Command::new("sh")
        .arg("-c")
        .arg("ulimit -v 2097152; exec \"$0\" \"$@\"")
        .arg(env!("CARGO_BIN_EXE_skin-validate"))
        .args([
            "mc",
            "--photons",
            "1000000",
            "--batches",
            "1000000",
            "--threads",
            "2",
        ])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "exit {:?}: {}",
        out.status.code(),
        String::from_utf8_lossy(&out.stderr)
    );
    // One photon per batch: the CSV row still reports every photon.
    let row: Vec<&str> = stdout.lines().nth(1).unwrap().split(',').collect();
    assert_eq!(row[5], "1000000", "{stdout}");
    // Light skin at 550 nm: diffuse reflectance near the exact 0.437 (±0.005 is > 10 standard
    // errors of 1e6 photons, whose standard error is about 5e-4).
    let r: f64 = row[0].parse().unwrap();
    assert!((r - 0.437).abs() < 0.005, "{r}");
}
