//! Build the maps' forward table (no cache) and report its wall and process CPU time, and the
//! interpolant's error against the exact model between the nodes.
//! Run: `cargo run --release -p skin-fit --features studies --example maps_table`.

use cpu_time::ProcessTime;
use skin_fit::maps::{ForwardTable, TableSize, u_of_melanin, v_of_hemoglobin};
use skin_fit::{ColourModel, FitOptions};
use skin_optics::lab::{Lab, delta_e_2000};
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let size = TableSize::default();
    let base = FitOptions::default().base;
    let (wall, cpu) = (Instant::now(), ProcessTime::now());
    let table = ForwardTable::build(size, base)?;
    println!(
        "table {}x{}x{} = {} exact colours: {:.2} s wall, {:.2} CPU-s on {} threads",
        size.melanin,
        size.eumelanin,
        size.hemoglobin,
        size.nodes(),
        wall.elapsed().as_secs_f64(),
        cpu.elapsed().as_secs_f64(),
        rayon::current_num_threads()
    );
    // Interpolant against the exact model at points between the nodes (a 7 × 5 × 7 lattice offset
    // from every node plane), over the skin ranges C_m 0.002–0.45, β_m 0–1, C_h 0.0015–0.09.
    let model = ColourModel::new(10.0, multipole::Method::Exact, base)?;
    let mut errors = Vec::new();
    for bi in 0..5 {
        let beta = 0.05 + 0.9 * f64::from(bi) / 4.0;
        let slice = table.slice(beta);
        for mi in 0..7 {
            let c_m = 0.002 * (0.45f64 / 0.002).powf(f64::from(mi) / 6.0);
            for hi in 0..7 {
                let c_h = 0.0015 * (0.09f64 / 0.0015).powf(f64::from(hi) / 6.0);
                let exact = model.lab(&model.skin(c_m, beta, c_h)?)?;
                let t = slice.lab(u_of_melanin(c_m), v_of_hemoglobin(c_h));
                let de = delta_e_2000(
                    exact,
                    Lab {
                        l: t[0],
                        a: t[1],
                        b: t[2],
                    },
                );
                errors.push((de, c_m, beta, c_h));
            }
        }
    }
    errors.sort_by(|a, b| a.0.total_cmp(&b.0));
    let n = errors.len();
    println!(
        "interpolant vs exact over {n} off-node skins: ΔE2000 median {:.4}, p95 {:.4}, max {:.4} (at C_m {:.4}, β_m {:.3}, C_h {:.4})",
        errors[n / 2].0,
        errors[(n * 95) / 100].0,
        errors[n - 1].0,
        errors[n - 1].1,
        errors[n - 1].2,
        errors[n - 1].3
    );
    Ok(())
}
