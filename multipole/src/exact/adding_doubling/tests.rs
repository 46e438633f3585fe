//! Closed forms, limits and reference values for the adding-doubling solver.

use super::*;
use skin_optics::Preset;

fn opts(n: usize) -> AddingDoublingOptions {
    AddingDoublingOptions::new(n, DEFAULT_G).expect("valid options")
}

/// A layer as (σa, σs (mm⁻¹), g, thickness (mm, infinite for a semi-infinite layer)).
type Spec = (f64, f64, f64, f64);

/// A medium of the layers `layers`, all of index `eta`, between air above and below.
struct Slab(LayeredMedium);

impl Slab {
    fn solve(&self, options: &AddingDoublingOptions) -> Result<SlabTotals, AddingDoublingError> {
        solve(&self.0, options)
    }
}

fn slab(layers: Vec<Spec>, eta: f64) -> Slab {
    let layers = layers
        .into_iter()
        .map(|(sa, ss, g, d)| {
            if d.is_infinite() {
                Layer::semi_infinite(sa, ss, g, eta)
            } else {
                Layer::slab(sa, ss, g, eta, d)
            }
            .expect("valid layer")
        })
        .collect();
    Slab(LayeredMedium::new(layers, 1.0, 1.0).expect("valid slab"))
}

fn layer(sigma_a: f64, sigma_s: f64, g: f64, d_mm: f64) -> Spec {
    (sigma_a, sigma_s, g, d_mm)
}

/// Semi-infinite medium given σa and σs' (σs = σs'/(1 − g)), air above a stack of index `eta`.
fn semi_infinite(sigma_a: f64, sigma_s_prime: f64, g: f64, eta: f64, n: usize) -> SlabTotals {
    let l = Layer::from_reduced(sigma_a, sigma_s_prime, g, eta, None).expect("valid layer");
    let medium = LayeredMedium::new(vec![l], 1.0, 1.0).expect("valid slab");
    solve(&medium, &opts(n)).expect("solves")
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

#[test]
fn non_absorbing_slab_conserves_energy() {
    for (eta, g, d) in [
        (1.0, 0.9, 1.0),
        (1.4, 0.9, 1.0),
        (1.4, 0.0, 0.3),
        (1.33, 0.5, 5.0),
    ] {
        for n in [8, 16, 32] {
            let t = slab(vec![layer(0.0, 10.0, g, d)], eta)
                .solve(&opts(n))
                .expect("solves");
            let sum = t.diffuse_reflectance + t.specular_reflectance + t.transmittance;
            assert!(
                (sum - 1.0).abs() < 1e-9,
                "eta {eta} g {g} d {d} n {n}: R + T = {sum}"
            );
            assert!(t.diffuse_reflectance > 0.0 && t.transmittance > 0.0);
        }
    }
}

#[test]
fn thin_index_matched_slab_transmits_everything() {
    let mut previous = 0.0;
    for d in [1e-1, 1e-2, 1e-3, 1e-4] {
        let t = slab(vec![layer(0.5, 5.0, 0.9, d)], 1.0)
            .solve(&opts(16))
            .expect("solves");
        // Loss is at most the collimated beam's interaction probability σt d.
        assert!(
            1.0 - t.transmittance <= 5.5 * d + 1e-12,
            "d {d}: T = {}",
            t.transmittance
        );
        assert!(t.transmittance > previous);
        previous = t.transmittance;
    }
    assert!(1.0 - previous < 1e-3);
    // The thinnest valid layer (thickness must be positive, `LayeredMedium`) is the identity.
    let zero = slab(vec![layer(0.5, 5.0, 0.9, f64::MIN_POSITIVE)], 1.0)
        .solve(&opts(16))
        .expect("solves");
    assert!((zero.transmittance - 1.0).abs() < 1e-14 && zero.diffuse_reflectance.abs() < 1e-14);
}

#[test]
fn pure_absorber_between_fresnel_faces_matches_closed_form() {
    // Only the normal beam is involved: T = (1 − F)² e^−τ / (1 − F² e^−2τ) and the light reflected by
    // the bottom face and escaping, F (1 − F)² e^−2τ / (1 − F² e^−2τ), F = F_r(0) = 1/36 at η = 1.4.
    let f = brdf::fresnel::normal_incidence_reflectance(1.4);
    for tau in [0.1, 1.0, 3.0] {
        let t = slab(vec![layer(tau, 0.0, 0.9, 1.0)], 1.4)
            .solve(&opts(16))
            .expect("solves");
        let e = (-tau).exp();
        let denom = 1.0 - f * f * e * e;
        assert!((t.transmittance - (1.0 - f).powi(2) * e / denom).abs() < 1e-13);
        assert!((t.diffuse_reflectance - f * (1.0 - f).powi(2) * e * e / denom).abs() < 1e-13);
        assert!((t.specular_reflectance - f).abs() < 1e-15);
    }
}

#[test]
fn splitting_a_layer_changes_nothing() {
    // Adding two thirds to one third of a slab must give the slab (up to the thin-layer start error).
    let whole = slab(vec![layer(0.3, 20.0, 0.9, 0.6)], 1.4)
        .solve(&opts(16))
        .expect("solves");
    let split = slab(
        vec![layer(0.3, 20.0, 0.9, 0.2), layer(0.3, 20.0, 0.9, 0.4)],
        1.4,
    )
    .solve(&opts(16))
    .expect("solves");
    assert!(rel(split.diffuse_reflectance, whole.diffuse_reflectance) < 1e-5);
    assert!(rel(split.transmittance, whole.transmittance) < 1e-5);
    let with_empty = slab(
        vec![
            layer(0.3, 20.0, 0.9, 0.6),
            layer(1.0, 1.0, 0.0, f64::MIN_POSITIVE),
        ],
        1.4,
    )
    .solve(&opts(16))
    .expect("solves");
    assert!(rel(with_empty.diffuse_reflectance, whole.diffuse_reflectance) < 1e-12);
}

/// Chandrasekhar's H-function for isotropic scattering of albedo ϖ: (H(1), ∫₀¹ H dμ), from the iteration
/// 1/H(μ) = √(1 − ϖ) + (ϖ/2) ∫₀¹ μ' H(μ') / (μ + μ') dμ' on a 200-point Gauss grid.
fn chandrasekhar_h(albedo: f64) -> (f64, f64) {
    let rule = quadrature::gauss(200, 0.0, 1.0);
    let mut h = vec![1.0; 200];
    let eval = |h: &[f64], mu: f64| {
        let s: f64 = rule
            .nodes
            .iter()
            .zip(&rule.weights)
            .zip(h)
            .map(|((&x, &w), &hx)| w * x * hx / (mu + x))
            .sum();
        1.0 / ((1.0 - albedo).sqrt() + 0.5 * albedo * s)
    };
    for _ in 0..20_000 {
        let next: Vec<f64> = rule.nodes.iter().map(|&mu| eval(&h, mu)).collect();
        let change = next
            .iter()
            .zip(&h)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        h = next;
        if change < 1e-14 {
            break;
        }
    }
    let moment = rule.weights.iter().zip(&h).map(|(w, v)| w * v).sum();
    (eval(&h, 1.0), moment)
}

#[test]
fn chandrasekhar_h_function_satisfies_its_moment_identity() {
    // Chandrasekhar, Radiative Transfer (1950) §39: ∫₀¹ H dμ = (2/ϖ)(1 − √(1 − ϖ)) exactly.
    for albedo in [0.5, 0.9, 0.99] {
        let (_, moment) = chandrasekhar_h(albedo);
        let exact = 2.0 / albedo * (1.0 - (1.0 - albedo).sqrt());
        assert!(
            (moment - exact).abs() < 1e-9,
            "albedo {albedo}: {moment} vs {exact}"
        );
    }
}

#[test]
fn isotropic_semi_infinite_matches_the_h_function() {
    // Plane albedo of a semi-infinite isotropic scatterer at normal incidence: r(1) = 1 − H(1) √(1 − ϖ)
    // (Chandrasekhar 1950; van de Hulst 1980). For ϖ = 0.99 this is 0.75272.
    for albedo in [0.5, 0.9, 0.99] {
        let exact = 1.0 - chandrasekhar_h(albedo).0 * (1.0 - albedo).sqrt();
        let got = slab(vec![layer(1.0 - albedo, albedo, 0.0, f64::INFINITY)], 1.0)
            .solve(&opts(16))
            .expect("solves")
            .diffuse_reflectance;
        assert!(rel(got, exact) < 1e-4, "albedo {albedo}: {got} vs {exact}");
        if albedo == 0.99 {
            assert!((got - 0.75272).abs() < 1e-4, "{got}");
        }
    }
}

/// Dipole total diffuse reflectance ([JMLH01]; docs/physics.md §3), restated here only as an independent
/// check: R = (α'/2)(1 + e^−(4/3)A√(3(1−α'))) e^−√(3(1−α')), A from the [JMLH01] F_dr fit.
fn dipole_total(albedo_prime: f64, eta: f64) -> f64 {
    let f_dr = -1.440 / (eta * eta) + 0.710 / eta + 0.668 + 0.0636 * eta;
    let a = (1.0 + f_dr) / (1.0 - f_dr);
    let s = (3.0 * (1.0 - albedo_prime)).sqrt();
    0.5 * albedo_prime * (1.0 + (-(4.0 / 3.0) * a * s).exp()) * (-s).exp()
}

#[test]
fn high_albedo_semi_infinite_approaches_the_dipole() {
    // docs/physics.md §3 check value: (σa, σs') = (0.01, 1) gives 0.61410 at η = 1.4.
    assert!((dipole_total(1.0 / 1.01, 1.4) - 0.61410).abs() < 1e-5);
    let f0 = brdf::fresnel::normal_incidence_reflectance(1.4);
    let sigma_a = 1.0 / 0.999 - 1.0; // reduced albedo α' = 0.999 with σs' = 1 mm⁻¹
    let exact = semi_infinite(sigma_a, 1.0, 0.9, 1.4, 32).diffuse_reflectance;
    let dipole = (1.0 - f0) * dipole_total(0.999, 1.4);
    assert!(
        rel(exact, dipole) < 0.02,
        "exact {exact} vs dipole {dipole}"
    );
}

// Independent exact-transport reference values (BENCHMARKS.md `## Exact method`: Monte Carlo and
// adding-doubling agree to 0.6%; quoted ±0.0008), per incident photon, specular excluded. Our tolerance: 0.5%.

#[test]
fn semi_infinite_references() {
    let weak = semi_infinite(0.01, 1.0, 0.9, 1.4, 32).diffuse_reflectance;
    assert!(rel(weak, 0.6040) < 0.005, "σa 0.01: {weak}");
    let strong = semi_infinite(0.5, 1.0, 0.9, 1.4, 32).diffuse_reflectance;
    assert!(rel(strong, 0.0713) < 0.005, "σa 0.5: {strong}");
}

#[test]
fn light_skin_references() {
    let skin = SkinParams::new(0.002, 0.5, 0.01, 0.25).expect("valid skin");
    for (nm, reference) in [(450.0, 0.4095), (550.0, 0.4370), (650.0, 0.6066)] {
        let lambda = Wavelength::new(nm).expect("visible");
        for n in [DEFAULT_QUADRATURE_POINTS, 32] {
            let r = skin_totals(&skin, lambda, &opts(n))
                .expect("solves")
                .diffuse_reflectance;
            assert!(
                rel(r, reference) < 0.005,
                "{nm} nm, {n} points: {r} vs {reference}"
            );
        }
    }
}

#[test]
fn quadrature_knob_converges() {
    // Default knob against 64 points: the measured discretisation error (BENCHMARKS.md). Light skin is
    // within 0.03%; the darkest skin (low-albedo epidermis) within 0.75%.
    for (skin, tolerance) in [
        (
            SkinParams::new(0.002, 0.5, 0.01, 0.25).expect("valid skin"),
            5e-4,
        ),
        (
            SkinParams::new(0.5, 0.9, 0.07, 0.25).expect("valid skin"),
            1e-2,
        ),
    ] {
        for nm in [400.0, 550.0, 700.0] {
            let lambda = Wavelength::new(nm).expect("visible");
            let fine = skin_totals(&skin, lambda, &opts(64))
                .expect("solves")
                .diffuse_reflectance;
            let default = skin_totals(&skin, lambda, &AddingDoublingOptions::default())
                .expect("solves")
                .diffuse_reflectance;
            assert!(
                rel(default, fine) < tolerance,
                "{nm} nm: {default} vs {fine}"
            );
        }
    }
}

mod properties {
    use super::*;
    use proptest::prelude::*;

    /// Physically valid skins ([DJ06] ranges) and a visible wavelength.
    fn skin_and_lambda() -> impl Strategy<Value = (f64, f64, f64, f64)> {
        (0.0..0.45f64, 0.0..=1.0f64, 0.001..=0.1f64, 400.0..=700.0f64)
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

        #[test]
        fn skin_totals_are_in_unit_interval_and_fall_with_melanin(
            (c_m, beta_m, c_h, nm) in skin_and_lambda()
        ) {
            let lambda = Wavelength::new(nm).expect("visible");
            let o = opts(12);
            let lighter = SkinParams::new(c_m, beta_m, c_h, 0.25).expect("valid skin");
            let darker = SkinParams::new(c_m + 0.05, beta_m, c_h, 0.25).expect("valid skin");
            let a = skin_totals(&lighter, lambda, &o).expect("solves");
            let b = skin_totals(&darker, lambda, &o).expect("solves");
            prop_assert!(a.diffuse_reflectance > 0.0 && a.diffuse_reflectance < 1.0);
            prop_assert!(a.absorbed() > 0.0 && a.absorbed() < 1.0);
            prop_assert!(b.diffuse_reflectance < a.diffuse_reflectance);
        }
    }
}

#[test]
fn reflectance_falls_as_absorption_rises() {
    let mut previous = 1.0;
    for sigma_a in [0.0, 0.01, 0.1, 1.0, 10.0] {
        let r = slab(
            vec![layer(sigma_a, 20.0, 0.9, 0.25), layer(0.05, 20.0, 0.9, 2.0)],
            1.4,
        )
        .solve(&opts(16))
        .expect("solves");
        assert!(r.diffuse_reflectance < previous && r.absorbed() >= -1e-12);
        previous = r.diffuse_reflectance;
    }
}

#[test]
fn bad_input_is_a_typed_error() {
    // The layers' own ranges are `LayeredMedium`'s (tested in `crate::layered`); here the solver's.
    assert!(matches!(
        AddingDoublingOptions::new(7, 0.9),
        Err(AddingDoublingError::OutOfRange {
            name: "quadrature_points",
            ..
        })
    ));
    assert!(matches!(
        AddingDoublingOptions::new(16, 1.0),
        Err(AddingDoublingError::OutOfRange { name: "g", .. })
    ));
    let top = Layer::slab(0.1, 1.0, 0.9, 1.4, 0.1).expect("valid");
    let bottom = Layer::semi_infinite(0.1, 1.0, 0.9, 1.3).expect("valid");
    let mixed = LayeredMedium::new(vec![top, bottom], 1.0, 1.0).expect("valid medium");
    assert!(matches!(
        solve(&mixed, &opts(16)),
        Err(AddingDoublingError::OutOfRange { value, .. }) if value == 1.3
    ));
}

#[test]
#[ignore = "prints the quadrature convergence table for BENCHMARKS.md"]
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

#[test]
#[ignore = "prints the dark-skin quadrature convergence for BENCHMARKS.md"]
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

#[test]
#[ignore = "prints multipole against exact totals for BENCHMARKS.md"]
fn print_multipole_against_exact() {
    use crate::skin::{Method, diffuse_reflectance};
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

#[test]
#[ignore = "prints on-CPU time per 31-λ skin set for BENCHMARKS.md (Linux; the machine is shared)"]
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

#[test]
#[ignore = "prints the worst quadrature error against 64 points for BENCHMARKS.md"]
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
