//! Per-texel epidermis thickness, BSSRDF against the volumetric reference (docs/physics.md §19.4):
//! the flat slab of `hetero_skin` with C_m 0.1 everywhere, its epidermis split at x = 0 into thin
//! (0.05 mm, x < 0: maps.exr's `thin_epidermis` flag) and normal (0.25 mm) skin, under a uniform
//! sky of spectral radiance 1, at 550 and 650 nm. First each skin alone (a uniform flag) for the
//! BSSRDF's homogeneous gap; then the radiance across the strip x ∈ [−4, 4] mm from the walk and
//! the BSSRDF (default rule), the region means (≥ 1 mm from the split) and the RMS relative
//! difference over the transition (|x| < 1 mm). Writes OUT/thin_split_<nm>.csv and OUT/thin.png.
//!
//!     cargo run --release -p validation --features studies --example hetero_thin -- OUT [SPP_VOL] [SPP_BSSRDF]

use render::integrator::IntegratorKind;
use render::testing::hetero::{SLAB_SIDE_MM, region, strip_columns, strip_scene, uniform_means};
use skin_plot::{LineChart, Panel, Series, save_png};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

const HALF_MM: f32 = 4.0;
const COLUMNS: usize = 64;
const MELANIN: f32 = 0.1;
const THIN_MM: f32 = 0.05;

/// maps.exr with C_m [`MELANIN`] and the thin-epidermis flag `flag(x)` over 512 × 1 texels.
fn write_maps(dir: &Path, flag: fn(f32) -> f32) -> anyhow::Result<()> {
    let n = 512;
    let h = 0.5 * SLAB_SIDE_MM;
    let flags = (0..n)
        .map(|i| flag(-h + (i as f32 + 0.5) * SLAB_SIDE_MM / n as f32))
        .collect();
    let bytes = render::texture::channels_exr_bytes_with(
        n,
        1,
        vec![("melanin", vec![MELANIN; n]), ("thin_epidermis", flags)],
        &[("thin_epidermis_mm", THIN_MM)],
    )
    .map_err(anyhow::Error::msg)?;
    std::fs::write(dir.join("maps.exr"), bytes)?;
    Ok(())
}

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let out = PathBuf::from(args.next().unwrap_or_else(|| "out/hetero".into()));
    let spp_vol: u32 = args.next().map_or(Ok(2048), |s| s.parse())?;
    let spp_bss: u32 = args.next().map_or(Ok(1024), |s| s.parse())?;
    std::fs::create_dir_all(&out)?;
    let start = cpu_time::ProcessTime::now();
    let keys = "maps = \"maps.exr\"";
    let x = |i: usize| -HALF_MM + (i as f32 + 0.5) * 2.0 * HALF_MM / COLUMNS as f32;
    let mut panels = Vec::new();
    for nm in [550.0f32, 650.0] {
        for (label, flag) in [("thin", (|_| 1.0) as fn(f32) -> f32), ("normal", |_| 0.0)] {
            let dir = tempfile::tempdir()?;
            write_maps(dir.path(), flag)?;
            let scene = strip_scene(dir.path(), HALF_MM, COLUMNS, keys);
            let [(v, vs), (b, bs)] =
                uniform_means(&scene, HALF_MM, COLUMNS, nm, (spp_vol / 4, spp_bss / 4));
            println!(
                "uniform {label} epidermis at {nm} nm: walk {v:.4} ± {vs:.4}, BSSRDF {b:.4} ± {bs:.4} ({:+.2}%)",
                100.0 * (b / v - 1.0)
            );
        }
        let dir = tempfile::tempdir()?;
        write_maps(dir.path(), |x| if x < 0.0 { 1.0 } else { 0.0 })?;
        let scene = strip_scene(dir.path(), HALF_MM, COLUMNS, keys);
        let vol = strip_columns(&scene, IntegratorKind::Volumetric, COLUMNS, nm, spp_vol, 1);
        let bss = strip_columns(&scene, IntegratorKind::Bssrdf, COLUMNS, nm, spp_bss, 2);
        let mut csv = String::from("x_mm,volumetric,volumetric_se,bssrdf,bssrdf_se\n");
        for i in 0..COLUMNS {
            let _ = writeln!(
                csv,
                "{:.4},{:.6},{:.6},{:.6},{:.6}",
                x(i),
                vol[i].0,
                vol[i].1,
                bss[i].0,
                bss[i].1
            );
        }
        std::fs::write(out.join(format!("thin_split_{nm}.csv")), csv)?;
        println!("## split thin/normal at {nm} nm (spp {spp_vol} volumetric, {spp_bss} BSSRDF)");
        for (label, from, to) in [("thin", -HALF_MM, -1.0), ("normal", 1.0, HALF_MM)] {
            let (v, vs) = region(&vol, HALF_MM, from, to);
            let (b, bs) = region(&bss, HALF_MM, from, to);
            println!(
                "| {label} | walk {v:.4} ± {vs:.4} | BSSRDF {b:.4} ± {bs:.4} ({:+.2}%) |",
                100.0 * (b / v - 1.0)
            );
        }
        let (mut s, mut n) = (0.0, 0.0);
        for i in (0..COLUMNS).filter(|&i| x(i).abs() < 1.0) {
            s += (bss[i].0 / vol[i].0 - 1.0).powi(2);
            n += 1.0;
        }
        println!(
            "transition (|x| < 1 mm) RMS relative difference: {:.2}%",
            100.0 * (s / n).sqrt()
        );
        let points = |c: &[(f64, f64)]| -> Vec<(f64, f64)> {
            c.iter()
                .enumerate()
                .map(|(i, c)| (f64::from(x(i)), c.0))
                .collect()
        };
        panels.push(Panel::Line(
            LineChart::new(
                format!("thin (x < 0, {THIN_MM} mm) / normal epidermis at {nm} nm"),
                "x (mm)",
                "radiance (sky = 1)",
            )
            .with_series(Series::scatter("volumetric", points(&vol)))
            .with_series(Series::line("BSSRDF (geometric)", points(&bss))),
        ));
    }
    save_png(&out.join("thin.png"), &panels, 1400, 500)?;
    println!(
        "{:.1} CPU-s; wrote {}",
        start.elapsed().as_secs_f64(),
        out.display()
    );
    Ok(())
}
