//! Throughput of the maps inversion on a synthetic texture: the inverse lookup grid's build, the
//! inversion of every texel, and the forward albedo, each in wall and process CPU seconds (on a
//! shared machine CPU time is the steadier figure; texels per CPU-second times the core count is
//! the rate an idle machine reaches).
//! Run: `cargo run --release -p skin-fit --features studies --example maps_throughput [-- TEXELS]`.

use cpu_time::ProcessTime;
use skin_fit::maps::{
    Eumelanin, Inverter, Lookup, MapsModel, MapsOptions, delta_e_2000_fast, hemoglobin_of_v,
    melanin_of_u, texel_lab,
};
use std::time::Instant;

fn timed<T>(what: &str, texels: usize, f: impl FnOnce() -> T) -> T {
    let (wall, cpu) = (Instant::now(), ProcessTime::now());
    let out = f();
    let (w, c) = (wall.elapsed().as_secs_f64(), cpu.elapsed().as_secs_f64());
    if texels > 0 {
        println!(
            "{what}: {w:.3} s wall, {c:.3} CPU-s: {:.2} M texels per CPU-s, {:.2} M texels/s wall",
            texels as f64 / c / 1e6,
            texels as f64 / w / 1e6
        );
    } else {
        println!("{what}: {w:.3} s wall, {c:.3} CPU-s");
    }
    out
}

/// Every texel through CIELAB, the lookup grid, one Gauss–Newton step and the residual ΔE2000,
/// in chunks of a function of its own so that
/// `valgrind --tool=callgrind --toggle-collect='*invert_chunk*'` counts them alone.
fn invert_all(inv: &Inverter, texels: &[[f32; 3]]) -> f64 {
    use rayon::prelude::*;
    texels
        .par_chunks(1 << 14)
        .map(|chunk| invert_chunk(inv, chunk))
        .sum::<f64>()
}

#[inline(never)]
fn invert_chunk(inv: &Inverter, texels: &[[f32; 3]]) -> f64 {
    texels
        .iter()
        .map(|t| {
            let target = texel_lab(*t).0;
            let r = inv.invert_fast(&target);
            delta_e_2000_fast(&target, &r.lab)
        })
        .sum::<f64>()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let n: usize = std::env::args()
        .nth(1)
        .map_or(Ok(4_000_000), |s| s.parse())?;
    let opts = MapsOptions {
        eumelanin: Eumelanin::Fixed(0.6),
        cache_dir: skin_io::cache::cache_dir(),
        lookup: Lookup::Always,
        ..MapsOptions::default()
    };
    let model = timed("forward table (cache)", 0, || MapsModel::load(&opts))?;
    println!("table cache: {}", model.cache_outcome());
    // Skins over the table (a scrambled lattice in u, v) with every tenth texel non-skin.
    let melanin: Vec<f32> = (0..n)
        .map(|k| melanin_of_u(((k * 7919) % 1000) as f64 / 999.0) as f32)
        .collect();
    let hemoglobin: Vec<f32> = (0..n)
        .map(|k| hemoglobin_of_v(((k * 104_729) % 997) as f64 / 996.0) as f32)
        .collect();
    let texels: Vec<[f32; 3]> = model
        .albedo(&melanin, 0.6, &hemoglobin)?
        .into_iter()
        .enumerate()
        .map(|(k, t)| match k % 30 {
            0 => [0.2, 0.2, 0.2],
            10 => [0.05, 0.4, 0.05],
            20 => [0.002, 0.002, 0.003],
            _ => t,
        })
        .collect();
    let slice = model.table().slice(0.6);
    timed("inverse lookup grid (one slice)", 0, || {
        Inverter::with_lookup(slice.clone())
    });
    let maps = timed("fit, lookup grid included", n, || {
        model.fit(&texels, None, &opts, &|_| {})
    })?;
    println!(
        "in gamut {} of {}, ΔE2000 median {:.4} p95 {:.4} max {:.3}",
        maps.summary.in_gamut, n, maps.summary.median_de, maps.summary.p95_de, maps.summary.max_de
    );
    let inv = Inverter::with_lookup(slice);
    timed(
        "inversion itself (texel → Lab → lookup → one step → ΔE2000)",
        n,
        || invert_all(&inv, &texels),
    );
    timed("texel → CIELAB only", n, || {
        use rayon::prelude::*;
        texels
            .par_iter()
            .with_min_len(1 << 14)
            .map(|t| texel_lab(*t).0[0])
            .sum::<f64>()
    });
    timed("texel → CIELAB → inversion (no ΔE2000)", n, || {
        use rayon::prelude::*;
        texels
            .par_iter()
            .with_min_len(1 << 14)
            .map(|t| inv.invert_fast(&texel_lab(*t).0).u)
            .sum::<f64>()
    });
    timed("albedo of the maps", n, || {
        model.albedo(&maps.melanin, 0.6, &maps.hemoglobin)
    })?;
    Ok(())
}
