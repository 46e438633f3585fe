//! Photons per CPU-second of our layered Monte Carlo and of MCML 1.2 ([WJZ95], the original C
//! program), one thread each, in the same run, on the same layers: light skin 550 nm, dark skin
//! 450 nm and the half-space σa 0.01, σs' 1 mm⁻¹ (`validation::mcml::cases`). MCML traces the `.mci`
//! of the reference data with one run (radial grid 0.01 mm × 1000, depth grid 0.05 mm × 200, one
//! angle); ours the same stack on a rayon pool of one thread with the same radial grid.
//!
//! CPU time: MCML's from the kernel's accounting of the waited-for child (`/proc/self/stat`
//! cutime + cstime, 10 ms ticks), ours from the worker thread's own on-CPU time
//! (`/proc/thread-self/schedstat`), so other load on the machine does not count (Linux only).
//! The two alternate `REPEATS` times per case; each line is one pair, the summary the median ratio.
//!
//! `cargo run --release -p validation --features studies --example mcml_side_by_side -- PATH_TO_MCML [PHOTONS] [REPEATS]`
//! (defaults 100,000 photons, 3 repeats; MCML built by its own build script, outside this tree).

use anyhow::Context;
use indicatif::{ProgressBar, ProgressStyle};
use std::path::PathBuf;
use validation::mcml::{self, DR_MM, McmlRun, NR, thread_cpu_seconds};
use validation::montecarlo::{McOptions, RadialGrid, run};

/// The cases timed.
const CASES: [&str; 3] = ["light-550", "dark-450", "half-space"];

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// Smallest and largest value.
fn range(v: &[f64]) -> (f64, f64) {
    v.iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &r| {
            (l.min(r), h.max(r))
        })
}

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let binary = PathBuf::from(
        args.next()
            .context("usage: mcml_side_by_side PATH_TO_MCML [PHOTONS] [REPEATS]")?,
    );
    let photons: u64 = args
        .next()
        .map(|s| s.parse())
        .transpose()?
        .unwrap_or(100_000);
    let repeats: usize = args.next().map(|s| s.parse()).transpose()?.unwrap_or(3);
    anyhow::ensure!(
        (2..=1_000_000_000).contains(&photons),
        "PHOTONS must be in [2, 1e9] (got {photons})"
    );
    anyhow::ensure!(
        (1..=100).contains(&repeats),
        "REPEATS must be in [1, 100] (got {repeats})"
    );
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    let grid = RadialGrid::new(DR_MM, NR)?;
    let bar = ProgressBar::new((CASES.len() * repeats) as u64).with_style(
        ProgressStyle::with_template("{bar:30} {pos}/{len} pairs of runs {elapsed}")?,
    );
    bar.tick();
    let mut summary = Vec::new();
    for name in CASES {
        let case = mcml::case(name)?;
        let runs = [McmlRun {
            output: format!("{name}.mco"),
            photons,
        }];
        let mci = mcml::mci(
            &case.stack,
            &runs,
            &format!("side-by-side speed run, {name}"),
        )?;
        let mut ratios = Vec::new();
        for rep in 0..repeats {
            let dir = tempfile::tempdir()?;
            let theirs = mcml::run_mcml(&binary, &mci, &runs, dir.path())?;
            let mcml_cpu = theirs
                .cpu_seconds
                .context("no child CPU time (Linux only)")?;
            let opts = McOptions::new(photons, 2, 1 + rep as u64)?.with_grid(grid);
            let (ours, our_cpu) = pool.install(|| {
                let t0 = thread_cpu_seconds();
                let r = run(&case.stack, &opts);
                (r, thread_cpu_seconds().zip(t0).map(|(b, a)| b - a))
            });
            let our_cpu = our_cpu.context("no thread CPU time (Linux only)")?;
            let (rate_mcml, rate_ours) = (photons as f64 / mcml_cpu, photons as f64 / our_cpu);
            ratios.push(rate_ours / rate_mcml);
            bar.inc(1);
            bar.suspend(|| eprintln!(
                "{name} #{rep}: MCML {rate_mcml:.0} photons/CPU-s ({mcml_cpu:.2} s, R_d {:.5}), \
                 ours {rate_ours:.0} photons/CPU-s ({our_cpu:.2} s, R_d {:.5} ± {:.5}), ratio {:.2}",
                theirs.outputs[0].diffuse_reflectance,
                ours.diffuse_reflectance.mean,
                ours.diffuse_reflectance.stderr,
                rate_ours / rate_mcml
            ));
            summary.push((name, rate_mcml, rate_ours));
        }
        let (lo, hi) = range(&ratios);
        bar.suspend(|| {
            eprintln!(
                "{name}: ratio median {:.2} (range {lo:.2}–{hi:.2})",
                median(ratios.clone())
            )
        });
    }
    bar.finish_and_clear();
    println!(
        "| case | MCML 1.2, photons / CPU-s | ours, photons / CPU-s | ours ÷ MCML (median, range) |"
    );
    println!("|---|---|---|---|");
    for name in CASES {
        let rows: Vec<_> = summary.iter().filter(|r| r.0 == name).collect();
        let ratios: Vec<f64> = rows.iter().map(|r| r.2 / r.1).collect();
        let (lo, hi) = range(&ratios);
        println!(
            "| {} | {:.0} | {:.0} | {:.2}× ({lo:.2}–{hi:.2}) |",
            mcml::case(name)?.description,
            median(rows.iter().map(|r| r.1).collect()),
            median(rows.iter().map(|r| r.2).collect()),
            median(ratios)
        );
    }
    println!("({photons} photons per run, {repeats} alternating pairs per case, one thread each)");
    Ok(())
}
