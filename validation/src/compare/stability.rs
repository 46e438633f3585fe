//! Study 3: where diffusion fails. The relative error of the multipole's observable reflectance
//! against MC for one slab over reduced albedo α' in [0.5, 0.999] × thickness in transport mean
//! free paths in [0.1, 100].
//!
//! The slab: σt' = σa + σs' = 1 mm⁻¹ (so the thickness in mm is in mean free paths), index 1.4 under
//! air on top and index-matched below (as the epidermis over the dermis), HG g = 0.9 in the MC with
//! σs = σs'/(1 − g). The albedo axis is uniform in −log(1 − α').

use super::{Settings, Summary, progress, write_csv};
use crate::montecarlo::{self, Layer, LayeredMedium, McOptions};
use multipole::diffusion::boundary::observable_reflectance;
use multipole::diffusion::{
    medium::Medium,
    slab::{Poles, Slab},
};
use skin_plot::{HeatMap, Panel, Series, save_png};
use std::path::Path;

/// Index of the slab, matching skin.
const ETA: f64 = 1.4;
/// Anisotropy of the MC.
const G: f64 = 0.9;

/// Relative error thresholds marked on the map.
pub const THRESHOLDS: [f64; 3] = [0.05, 0.20, 0.50];

/// Write `stability.csv` and `stability.png`; add the fraction of cells past each threshold.
pub fn run(settings: &Settings, out: &Path, summary: &mut Summary) -> anyhow::Result<()> {
    let n = settings.stability_cells;
    // Cell centres: 1 − α' log-spaced over [0.001, 0.5], thickness log-spaced over [0.1, 100].
    let one_minus = |i: usize| 0.5 * (0.001f64 / 0.5).powf((i as f64 + 0.5) / n as f64);
    let thick = |j: usize| 0.1 * 1000f64.powf((j as f64 + 0.5) / n as f64);
    let bar = progress((n * n) as u64, "stability cells");
    let mut values = vec![f64::NAN; n * n];
    let mut rows = Vec::new();
    let mut marks: Vec<Vec<(f64, f64)>> = vec![Vec::new(); THRESHOLDS.len()];
    for j in 0..n {
        for i in 0..n {
            let albedo = 1.0 - one_minus(i);
            let d = thick(j);
            let (sigma_a, sigma_s_prime) = (1.0 - albedo, albedo);
            let slab = Slab::new(Medium::new(sigma_a, sigma_s_prime)?, d, ETA, 1.0)?;
            let diffusion = observable_reflectance(slab.total_reflectance(Poles::Exact), ETA);
            let layer = Layer::from_reduced(sigma_a, sigma_s_prime, G, ETA, Some(d))?;
            let stack = LayeredMedium::new(vec![layer], 1.0, ETA)?;
            let opts = McOptions::new(settings.stability_photons, 8, settings.seed)?;
            let mc = montecarlo::run(&stack, &opts);
            let rd = mc.diffuse_reflectance;
            let rel = (diffusion - rd.mean) / rd.mean;
            // Colour: log10 of |relative error| (so 5%, 20%, 50% are evenly readable).
            values[j * n + i] = rel.abs().max(1e-4).log10();
            let x = -(1.0 - albedo).log10();
            // One mark per cell: the highest threshold exceeded (a NaN error counts as failed).
            if let Some(k) = THRESHOLDS
                .iter()
                .rposition(|t| rel.is_nan() || rel.abs() > *t)
            {
                marks[k].push((x, d));
            }
            rows.push(format!(
                "{albedo:.6},{d:.5},{diffusion:.6},{:.6},{:.6},{rel:.5}",
                rd.mean, rd.stderr
            ));
            bar.inc(1);
        }
    }
    bar.finish_and_clear();
    let cells = (n * n) as f64;
    for (k, t) in THRESHOLDS.iter().enumerate() {
        let beyond: usize = marks[k..].iter().map(Vec::len).sum();
        summary.push(
            "3 stability",
            &format!("relative error beyond ±{:.0}%", 100.0 * t),
            format!("{:.0}% of the map", 100.0 * beyond as f64 / cells),
            "α' ∈ [0.5, 0.999], d ∈ [0.1, 100] mfp".into(),
        );
    }
    write_csv(
        &out.join("stability.csv"),
        "albedo_prime,thickness_mfp,multipole,monte_carlo,monte_carlo_stderr,relative_error",
        &rows,
    )?;
    let overlay = THRESHOLDS
        .iter()
        .zip(marks)
        .zip([[255, 255, 255], [255, 150, 0], [230, 0, 0]])
        .map(|((t, pts), c)| Series::scatter(format!("> {:.0}%", 100.0 * t), pts).with_color(c))
        .collect();
    let map = HeatMap {
        title: "Diffusion's error vs Monte Carlo: slab (η 1.4 above, matched below)".into(),
        x_label: "−log10(1 − α')  (α' = 0.5 … 0.999)".into(),
        y_label: "thickness (transport mean free paths)".into(),
        value_label: "log10 |relative error|".into(),
        x_range: (-(0.5f64).log10(), 3.0),
        y_range: (0.1, 100.0),
        log_x: false,
        log_y: true,
        nx: n,
        ny: n,
        values,
        value_range: Some((-3.0, 0.5)),
        overlay,
    };
    save_png(&out.join("stability.png"), &[Panel::Heat(map)], 1000, 800)?;
    Ok(())
}
