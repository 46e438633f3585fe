//! Heterogeneous skin, BSSRDF against the volumetric reference (docs/physics.md §19.4): a flat
//! slab whose epidermis is split at x = 0 into dark (C_m 0.3, x < 0) and light (C_m 0.02) skin over
//! the same dermis, and a freckle (a 1-mm disc of C_m 0.15 in C_m 0.02 skin), under a uniform sky
//! of spectral radiance 1, at 550 and 650 nm. For each case and wavelength: the radiance across
//! the strip x ∈ [−4, 4] mm from the volumetric walk and from the BSSRDF under each profile rule,
//! the region means (≥ 1 mm from the boundary) and the RMS relative difference over the
//! transition (|x − boundary| < 1 mm). Writes OUT/hetero_<case>_<nm>.csv and OUT/hetero.png.
//!
//!     cargo run --release -p validation --features studies --example hetero_skin -- OUT [SPP_VOL] [SPP_BSSRDF]

use render::integrator::IntegratorKind;
use render::material::hetero::ProfileBlend;
use render::testing::hetero::{melanin_exr, region, strip_columns, strip_scene, uniform_means};
use skin_plot::{LineChart, Panel, Series, save_png};
use std::fmt::Write as _;
use std::path::PathBuf;

const HALF_MM: f32 = 4.0;
const COLUMNS: usize = 64;

/// A case: name, the melanin map (over x, y mm), and the regions compared.
struct Case {
    name: &'static str,
    melanin: fn(f32, f32) -> f32,
    /// (label, from mm, to mm) of each region ≥ 1 mm from a boundary.
    regions: &'static [(&'static str, f32, f32)],
    /// The boundary's distance from x = 0 along the strip, mm (the transition is within 1 mm).
    boundaries: &'static [f32],
}

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let out = PathBuf::from(args.next().unwrap_or_else(|| "out/hetero".into()));
    let spp_vol: u32 = args.next().map_or(Ok(2048), |s| s.parse())?;
    let spp_bss: u32 = args.next().map_or(Ok(1024), |s| s.parse())?;
    std::fs::create_dir_all(&out)?;
    let cases = [
        Case {
            name: "split",
            melanin: |x, _| if x < 0.0 { 0.3 } else { 0.02 },
            regions: &[("dark", -HALF_MM, -1.0), ("light", 1.0, HALF_MM)],
            boundaries: &[0.0],
        },
        Case {
            name: "freckle",
            melanin: |x, y| if x * x + y * y <= 0.25 { 0.15 } else { 0.02 },
            regions: &[
                ("left", -HALF_MM, -1.5),
                ("centre", -0.1, 0.1),
                ("right", 1.5, HALF_MM),
            ],
            boundaries: &[-0.5, 0.5],
        },
    ];
    let start = cpu_time::ProcessTime::now();
    // The homogeneous gap: each side's skin alone, BSSRDF against the walk over the whole strip.
    let uniform_dir = tempfile::tempdir()?;
    for nm in [550.0f32, 650.0] {
        for cm in [0.02, 0.15, 0.3] {
            let scene = strip_scene(
                uniform_dir.path(),
                HALF_MM,
                COLUMNS,
                &format!("melanin = {cm}"),
            );
            let [(v, vs), (b, bs)] =
                uniform_means(&scene, HALF_MM, COLUMNS, nm, (spp_vol / 4, spp_bss / 4));
            println!(
                "uniform C_m {cm} at {nm} nm: walk {v:.4} ± {vs:.4}, BSSRDF {b:.4} ± {bs:.4} ({:+.2}%)",
                100.0 * (b / v - 1.0)
            );
        }
    }
    let mut panels = Vec::new();
    for case in &cases {
        let dir = tempfile::tempdir()?;
        let side = 512;
        let rows = if case.name == "split" { 1 } else { side };
        std::fs::write(
            dir.path().join("maps.exr"),
            melanin_exr(side, rows, case.melanin),
        )?;
        for nm in [550.0f32, 650.0] {
            let keys =
                |blend: ProfileBlend| format!("maps = \"maps.exr\"\nprofile_blend = \"{blend}\"");
            let scene = strip_scene(dir.path(), HALF_MM, COLUMNS, &keys(ProfileBlend::default()));
            let vol = strip_columns(&scene, IntegratorKind::Volumetric, COLUMNS, nm, spp_vol, 1);
            let mut bss = Vec::new();
            for blend in ProfileBlend::ALL {
                let scene = strip_scene(dir.path(), HALF_MM, COLUMNS, &keys(blend));
                bss.push((
                    blend,
                    strip_columns(&scene, IntegratorKind::Bssrdf, COLUMNS, nm, spp_bss, 2),
                ));
            }
            let x = |i: usize| -HALF_MM + (i as f32 + 0.5) * 2.0 * HALF_MM / COLUMNS as f32;
            let mut csv = String::from("x_mm,volumetric,volumetric_se");
            for (b, _) in &bss {
                let _ = write!(csv, ",bssrdf_{b},bssrdf_{b}_se");
            }
            csv.push('\n');
            for i in 0..COLUMNS {
                let _ = write!(csv, "{:.4},{:.6},{:.6}", x(i), vol[i].0, vol[i].1);
                for (_, c) in &bss {
                    let _ = write!(csv, ",{:.6},{:.6}", c[i].0, c[i].1);
                }
                csv.push('\n');
            }
            std::fs::write(out.join(format!("hetero_{}_{nm}.csv", case.name)), csv)?;
            println!(
                "## {} at {nm} nm (spp {spp_vol} volumetric, {spp_bss} BSSRDF)",
                case.name
            );
            println!(
                "| region | volumetric | {} |",
                bss.iter()
                    .map(|(b, _)| format!("BSSRDF {b}"))
                    .collect::<Vec<_>>()
                    .join(" | ")
            );
            for &(label, from, to) in case.regions {
                let (v, vs) = region(&vol, HALF_MM, from, to);
                let cells: Vec<String> = bss
                    .iter()
                    .map(|(_, c)| {
                        let (b, bs) = region(c, HALF_MM, from, to);
                        format!("{b:.4} ± {bs:.4} ({:+.2}%)", 100.0 * (b / v - 1.0))
                    })
                    .collect();
                println!("| {label} | {v:.4} ± {vs:.4} | {} |", cells.join(" | "));
            }
            let near = |i: usize| case.boundaries.iter().any(|b| (x(i) - b).abs() < 1.0);
            let rms: Vec<String> = bss
                .iter()
                .map(|(b, c)| {
                    let (mut s, mut n) = (0.0, 0.0);
                    for i in (0..COLUMNS).filter(|&i| near(i)) {
                        s += (c[i].0 / vol[i].0 - 1.0).powi(2);
                        n += 1.0;
                    }
                    format!("{b} {:.2}%", 100.0 * (s / n).sqrt())
                })
                .collect();
            println!(
                "transition (|x − boundary| < 1 mm) RMS relative difference: {}",
                rms.join(", ")
            );
            let mut chart = LineChart::new(
                format!("{} at {nm} nm", case.name),
                "x (mm)",
                "radiance (sky = 1)",
            )
            .with_series(Series::scatter(
                "volumetric",
                vol.iter()
                    .enumerate()
                    .map(|(i, c)| (f64::from(x(i)), c.0))
                    .collect(),
            ));
            for (b, c) in &bss {
                chart = chart.with_series(Series::line(
                    format!("BSSRDF {b}"),
                    c.iter()
                        .enumerate()
                        .map(|(i, c)| (f64::from(x(i)), c.0))
                        .collect(),
                ));
            }
            panels.push(Panel::Line(chart));
        }
    }
    save_png(&out.join("hetero.png"), &panels, 1400, 1000)?;
    println!(
        "{:.1} CPU-s; wrote {}",
        start.elapsed().as_secs_f64(),
        out.display()
    );
    Ok(())
}
