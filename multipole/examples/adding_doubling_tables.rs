//! The adding-doubling tables behind BENCHMARKS.md: quadrature convergence (light and dark skin),
//! the multipole against the exact totals, on-CPU time per 31-wavelength skin spectrum, and the worst
//! quadrature error against 64 points.
//!
//! `cargo run --release -p multipole --features studies --example adding_doubling_tables`

use multipole::exact::adding_doubling::{
    AddingDoublingOptions, DEFAULT_G, SlabTotals, skin_totals, skin_totals_spectrum, solve,
};
use multipole::skin::diffuse_reflectance;
use multipole::{Layer, LayeredMedium, Method};
use skin_optics::{Preset, SkinParams, Wavelength, WavelengthGrid};

fn opts(n: usize) -> AddingDoublingOptions {
    AddingDoublingOptions::new(n, DEFAULT_G).expect("valid options")
}

/// Semi-infinite medium given σa and σs' (mm⁻¹), air above a medium of index `eta`.
fn semi_infinite(sigma_a: f64, sigma_s_prime: f64, g: f64, eta: f64, n: usize) -> SlabTotals {
    let l = Layer::from_reduced(sigma_a, sigma_s_prime, g, eta, None).expect("valid layer");
    let medium = LayeredMedium::new(vec![l], 1.0, 1.0).expect("valid slab");
    solve(&medium, &opts(n)).expect("solves")
}

fn main() {
    print_convergence_table();
    println!();
    print_dark_convergence_table();
    println!();
    print_multipole_against_exact();
    println!();
    print_cpu_time_per_spectrum();
    println!();
    print_worst_error_against_64_points();
}

fn print_convergence_table() {
    let skin = SkinParams::new(0.002, 0.5, 0.01, 0.25).expect("valid skin");
    println!("| points | σa 0.01 | σa 0.5 | light 450 | light 550 | light 650 |");
    for n in [8, 16, 24, 32, 48, 64] {
        let a = semi_infinite(0.01, 1.0, 0.9, 1.4, n).diffuse_reflectance;
        let b = semi_infinite(0.5, 1.0, 0.9, 1.4, n).diffuse_reflectance;
        let s: Vec<f64> = [450.0, 550.0, 650.0]
            .iter()
            .map(|&nm| {
                skin_totals(&skin, Wavelength::new(nm).expect("nm"), &opts(n))
                    .expect("solves")
                    .diffuse_reflectance
            })
            .collect();
        println!(
            "| {n} | {a:.5} | {b:.5} | {:.5} | {:.5} | {:.5} |",
            s[0], s[1], s[2]
        );
    }
}

fn print_dark_convergence_table() {
    let skin = SkinParams::new(0.5, 0.9, 0.07, 0.25).expect("valid skin");
    println!("| points | 400 nm | 450 nm | 550 nm | 650 nm | 700 nm |");
    for n in [8, 16, 24, 32, 48, 64] {
        let row: Vec<String> = [400.0, 450.0, 550.0, 650.0, 700.0]
            .iter()
            .map(|&nm| {
                let r = skin_totals(&skin, Wavelength::new(nm).expect("nm"), &opts(n))
                    .expect("solves")
                    .diffuse_reflectance;
                format!("{r:.5}")
            })
            .collect();
        println!("| {n} | {} |", row.join(" | "));
    }
}

fn print_multipole_against_exact() {
    println!(
        "| skin (C_m, β_m, C_h) | exact 450 / 550 / 650 nm | multipole / exact − 1, 400–700 nm |"
    );
    for (c_m, beta_m, c_h) in [
        (0.002, 0.5, 0.01),
        (0.05, 0.7, 0.02),
        (0.25, 0.9, 0.04),
        (0.5, 0.9, 0.07),
    ] {
        let skin = SkinParams::new(c_m, beta_m, c_h, 0.25).expect("valid skin");
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        let mut shown = Vec::new();
        for nm in (400..=700).step_by(10) {
            let lambda = Wavelength::new(f64::from(nm)).expect("visible");
            let e = diffuse_reflectance(&skin, lambda, Method::Exact).expect("solves");
            let m = diffuse_reflectance(&skin, lambda, Method::Multipole).expect("solves");
            lo = lo.min(m / e - 1.0);
            hi = hi.max(m / e - 1.0);
            if nm % 100 == 50 {
                shown.push(format!("{e:.4}"));
            }
        }
        println!(
            "| {c_m}, {beta_m}, {c_h} | {} | {:+.1}% to {:+.1}% |",
            shown.join(" / "),
            100.0 * lo,
            100.0 * hi
        );
    }
}

fn print_cpu_time_per_spectrum() {
    // Thread CPU time: on a loaded 2-core machine, wall-clock criterion figures overstate.
    let cpu_ns = || cpu_time::ThreadTime::now().as_duration().as_nanos() as f64;
    let grid = WavelengthGrid::visible();
    println!("| points | light: CPU ms per 31 λ | dark: CPU ms per 31 λ |");
    for n in [8, 16, 24, 32] {
        let o = opts(n);
        let row: Vec<String> = [Preset::Light, Preset::Dark]
            .iter()
            .map(|&p| {
                let skin = SkinParams::preset(p);
                let reps = 10;
                let start = cpu_ns();
                for _ in 0..reps {
                    std::hint::black_box(skin_totals_spectrum(&skin, &grid, &o).expect("solves"));
                }
                let ms = (cpu_ns() - start) * 1e-6 / f64::from(reps);
                format!("{ms:.1}")
            })
            .collect();
        println!("| {n} | {} |", row.join(" | "));
    }
}

fn print_worst_error_against_64_points() {
    // Four skins from light to dark, 400–700 nm every 20 nm; observable diffuse reflectance.
    let skins = [
        [0.002, 0.5, 0.01],
        [0.05, 0.7, 0.02],
        [0.25, 0.9, 0.04],
        [0.5, 0.9, 0.07],
    ];
    let lambdas: Vec<Wavelength> = (0..16)
        .map(|i| Wavelength::new(400.0 + 20.0 * f64::from(i)).expect("visible"))
        .collect();
    let reference: Vec<Vec<f64>> = skins
        .iter()
        .map(|p| {
            let skin = SkinParams::new(p[0], p[1], p[2], 0.25).expect("valid skin");
            lambdas
                .iter()
                .map(|&l| {
                    skin_totals(&skin, l, &opts(64))
                        .expect("solves")
                        .diffuse_reflectance
                })
                .collect()
        })
        .collect();
    println!("| points | light (C_m 0.002) | C_m 0.05 | C_m 0.25 | C_m 0.5 |");
    for n in [8, 12, 16, 20, 24, 32, 48] {
        let row: Vec<String> = skins
            .iter()
            .zip(&reference)
            .map(|(p, r)| {
                let skin = SkinParams::new(p[0], p[1], p[2], 0.25).expect("valid skin");
                let worst = lambdas
                    .iter()
                    .zip(r)
                    .map(|(&l, &r64)| {
                        let v = skin_totals(&skin, l, &opts(n))
                            .expect("solves")
                            .diffuse_reflectance;
                        (v / r64 - 1.0).abs()
                    })
                    .fold(0.0f64, f64::max);
                format!("{:.2}%", 100.0 * worst)
            })
            .collect();
        println!("| {n} | {} |", row.join(" | "));
    }
}
