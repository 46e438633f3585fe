//! CPU time of one full spectral set (31 wavelengths, 400–700 nm, two layers, 256 radii to the
//! 99.9% radius) on one thread, robust to a loaded machine: it reads this thread's on-CPU time (`cpu-time`)
//! besides the wall clock.
//!
//! `cargo run --release -p multipole --features studies --example spectral_timing [ITERATIONS [METHOD]]` (default 200,
//! multipole; `exact` times adding-doubling totals with the shape table's profiles, the table
//! built or read from its cache before timing).

use multipole::ProfileOptions;
use multipole::skin::{Method, SpectralProfiles};
use skin_optics::{Preset, SkinParams, WavelengthGrid};
use std::time::Instant;

/// Nanoseconds this thread has spent on a CPU.
fn thread_cpu_ns() -> Option<u64> {
    u64::try_from(cpu_time::ThreadTime::now().as_duration().as_nanos()).ok()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let n: usize = std::env::args()
        .nth(1)
        .map(|s| s.parse())
        .transpose()?
        .unwrap_or(200);
    let method: Method = std::env::args()
        .nth(2)
        .map(|s| s.parse())
        .transpose()?
        .unwrap_or(Method::Multipole);
    let grid = WavelengthGrid::visible();
    let opts = ProfileOptions::default();
    // A 1-thread pool that runs on this thread: `install` executes the closure on the pool's worker,
    // so time is measured inside it.
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    for preset in [Preset::Light, Preset::Medium, Preset::Dark] {
        let skin = SkinParams::preset(preset);
        let (wall, cpu) = pool.install(
            || -> Result<(f64, Option<f64>), multipole::MultipoleError> {
                SpectralProfiles::new(&skin, &grid, method, &opts)?; // warm the shared tables
                let (t, c) = (Instant::now(), thread_cpu_ns());
                for _ in 0..n {
                    std::hint::black_box(SpectralProfiles::new(&skin, &grid, method, &opts)?);
                }
                let cpu = match (c, thread_cpu_ns()) {
                    (Some(a), Some(b)) => Some((b - a) as f64 / n as f64 / 1e6),
                    _ => None,
                };
                Ok((t.elapsed().as_secs_f64() / n as f64 * 1e3, cpu))
            },
        )?;
        let cpu = cpu.map_or("n/a".to_string(), |c| format!("{c:.3} ms"));
        println!(
            "{:<6} 31 λ x 256 radii, {method}: wall {wall:.3} ms, on-CPU {cpu} per set",
            preset.name()
        );
    }
    Ok(())
}
