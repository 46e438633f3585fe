//! Writes the MCML 1.2 reference data of `validation/data/mcml/`: for each case of
//! `validation::mcml::cases`, the `.mci` input (the layers our code builds, in MCML's cm units) and,
//! after running MCML on it, the means and standard errors over its independent runs as CSV.
//!
//! `cargo run --release -p validation --features studies --example mcml_reference -- PATH_TO_MCML [RUNS] [PHOTONS_PER_RUN] [NAME...]`
//! (defaults 20 runs × 100,000 photons, every case; names pick cases; MCML is built by its own
//! build script, outside this tree).
//! Cases run in parallel on the rayon pool. MCML seeds its generator from the clock, so a re-run
//! gives other numbers within the stated standard errors.

use anyhow::Context;
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use validation::mcml::{self, DR_MM, McmlRun, ReferenceData};

/// Write `text` to `path` atomically (a temporary file in the same directory, then renamed).
fn write_atomic(path: &Path, text: &str) -> anyhow::Result<()> {
    use std::io::Write as _;
    let dir = path.parent().context("output path has no directory")?;
    let mut tmp = tempfile::NamedTempFile::new_in(dir)?;
    tmp.write_all(text.as_bytes())?;
    tmp.persist(path)?;
    Ok(())
}

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let binary = PathBuf::from(
        args.next()
            .context("usage: mcml_reference PATH_TO_MCML [RUNS] [PHOTONS_PER_RUN]")?,
    );
    let runs: u32 = args.next().map(|s| s.parse()).transpose()?.unwrap_or(20);
    let photons: u64 = args
        .next()
        .map(|s| s.parse())
        .transpose()?
        .unwrap_or(100_000);
    anyhow::ensure!(runs >= 2, "RUNS must be at least 2 (got {runs})");
    anyhow::ensure!(
        (1..=1_000_000_000).contains(&photons),
        "PHOTONS_PER_RUN must be in [1, 1e9] (got {photons})"
    );
    let out = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/mcml");
    std::fs::create_dir_all(&out)?;
    let only: Vec<String> = args.collect();
    let cases: Vec<_> = mcml::cases()?
        .into_iter()
        .filter(|c| only.is_empty() || only.iter().any(|n| n == c.name))
        .collect();
    let bar = ProgressBar::new(cases.len() as u64).with_style(ProgressStyle::with_template(
        "{bar:30} {pos}/{len} MCML cases {elapsed}",
    )?);
    bar.tick();
    let command = format!(
        "cargo run --release -p validation --example mcml_reference -- MCML {runs} {photons}{}",
        only.iter().map(|n| format!(" {n}")).collect::<String>()
    );
    cases.par_iter().try_for_each(|case| -> anyhow::Result<()> {
        let list: Vec<McmlRun> = (0..runs)
            .map(|k| McmlRun {
                output: format!("{}-{k:02}.mco", case.name),
                photons,
            })
            .collect();
        let comment = format!(
            "MCML 1.2 input, case {}: {runs} independent runs of {photons} photons.\nWritten by: {command}",
            case.name
        );
        let mci = mcml::mci(&case.stack, &list, &comment)?;
        let dir = tempfile::tempdir()?;
        let process = mcml::run_mcml(&binary, &mci, &list, dir.path())?;
        let data = ReferenceData::from_runs(&process.outputs, photons, DR_MM)?;
        let header = format!(
            "MCML 1.2 (Wang, Jacques & Zheng 1995) reference, case {} ({}); input {}.mci.\n\
             mean and standard error over {runs} independent MCML runs of {photons} photons; per incident photon.\n\
             rd_r: R_d(r) in mm^-2 on annuli i of {DR_MM} mm from r = 0; the last annulus holds all weight beyond it.\n\
             Written by: {command}",
            case.name, case.description, case.name
        );
        write_atomic(&out.join(format!("{}.mci", case.name)), &mci)?;
        write_atomic(&out.join(format!("{}.csv", case.name)), &data.to_csv(&header))?;
        bar.inc(1);
        bar.suspend(|| eprintln!(
            "{}: Rd {:.5} ± {:.5}, A {:.5}, Tt {:.2e}",
            case.name,
            data.diffuse_reflectance.mean,
            data.diffuse_reflectance.stderr,
            data.absorbed.mean,
            data.transmittance.mean
        ));
        Ok(())
    })?;
    bar.finish();
    Ok(())
}
