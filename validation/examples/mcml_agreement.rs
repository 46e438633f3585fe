//! Our Monte Carlo against the committed MCML 1.2 data (`validation/data/mcml/`) at any photon
//! count: per case the z-score of every total and radial group (`validation::mcml::compare`; the
//! tests run the same comparison with few photons), their largest |z| and mean z² (≈ 1 when the two
//! codes agree and both errors are right).
//!
//! `cargo run --release -p validation --features studies --example mcml_agreement [PHOTONS] [CASE…]`
//! (default 10⁶ photons in 40 runs, every case).

use indicatif::{ProgressBar, ProgressStyle};
use std::path::Path;
use validation::mcml::{self, ReferenceData};

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let photons: u64 = args
        .next()
        .map(|s| s.parse())
        .transpose()?
        .unwrap_or(1_000_000);
    anyhow::ensure!(
        (4_000..=1_000_000_000).contains(&photons),
        "PHOTONS must be in [4000, 1e9] (got {photons})"
    );
    let mut names: Vec<String> = args.collect();
    if names.is_empty() {
        names = mcml::cases()?.iter().map(|c| c.name.to_string()).collect();
    }
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/mcml");
    let bar = ProgressBar::new(names.len() as u64).with_style(ProgressStyle::with_template(
        "{bar:30} {pos}/{len} cases {elapsed}",
    )?);
    bar.tick();
    println!("| case | MCML photons | our photons | comparisons | max abs z | mean z² |");
    println!("|---|---|---|---|---|---|");
    for name in names {
        let case = mcml::case(&name)?;
        let reference =
            ReferenceData::parse(&std::fs::read_to_string(dir.join(format!("{name}.csv")))?)?;
        let c = mcml::compare(&case, &reference, 40, photons / 40, 0xA6EE, 200.0, 5e-4)?;
        bar.inc(1);
        bar.suspend(|| {
            eprintln!("{name}:\n{}", c.table());
            println!(
                "| {} | {} | {} | {} | {:.2} | {:.2} |",
                case.description,
                reference.photons(),
                photons / 40 * 40,
                c.rows.len(),
                c.max_abs_z(),
                c.mean_z2()
            );
        });
    }
    bar.finish_and_clear();
    Ok(())
}
