//! The default exact-profile shape (`ExactShape::Table`) and the run-time Monte Carlo shape
//! (4,000 escapes) against an independent layered Monte Carlo reference (seed 7), for the darkest
//! skins of the parameter box in the blue and one light skin: the energy-weighted error on 0.02 mm
//! annuli (`validation::shape_error`, with the reference's own noise term) and, on a geometric
//! grid from 0.001 mm, the table's energy per radial band relative to the reference's.
//!
//! `cargo run --release -p validation --features studies --example dark_table -- [REF_PHOTONS [TABLE_PHOTONS
//! [DEPTHS_PER_OCTAVE [RADIAL_PER_DECADE [ALPHA_PER_DECADE]]]]]` (defaults 2·10⁶ and the table's
//! defaults; set `SKIN_CACHE_DIR` to keep other tables apart).
use multipole::ProfileOptions;
use multipole::skin::{ExactShape, ShapeTableOptions, exact_profile};
use skin_optics::{SkinParams, Wavelength};
use validation::montecarlo::{DEFAULT_G, LayeredMedium, McOptions, RadialGrid, run};
use validation::shape_error::{annulus_energy, energy_error};

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let photons: u64 = args.get(1).map_or(Ok(2_000_000), |s| s.parse())?;
    let p = |i: usize, d: u32| args.get(i).map_or(Ok(d), |s| s.parse());
    let opts = ShapeTableOptions {
        photons: args.get(2).map_or(Ok(500_000), |s| s.parse())?,
        depths_per_octave: p(3, 4)?,
        radial_per_decade: p(4, 16)?,
        alpha_per_decade: p(5, 8)?,
        ..ShapeTableOptions::default()
    };
    for (c_m, b, c_h, nm) in [
        (0.5, 0.9, 0.07, 400.0),
        (0.5, 0.9, 0.07, 450.0),
        (0.25, 0.9, 0.04, 400.0),
        (0.5, 0.9, 0.07, 550.0),
        (0.02, 0.5, 0.02, 450.0),
    ] {
        let skin = SkinParams::new(c_m, b, c_h, 0.25)?;
        let lambda = Wavelength::new(nm)?;
        let c = skin.coefficients(lambda);
        let ss = c.epidermis.sigma_s_prime / (1.0 - DEFAULT_G);
        let t = std::time::Instant::now();
        let tp = exact_profile(
            &skin,
            lambda,
            ExactShape::Table(opts),
            &ProfileOptions::default(),
        )?;
        let dt = t.elapsed().as_secs_f64();
        let mcp = exact_profile(
            &skin,
            lambda,
            ExactShape::MonteCarlo { escapes: 4000 },
            &ProfileOptions::default(),
        )?;
        let stack = LayeredMedium::skin(&skin, lambda, DEFAULT_G)?;
        let mc = run(
            &stack,
            &McOptions::new(photons, 16, 7)?.with_grid(RadialGrid::new(0.02, 300)?),
        );
        let (e, n) = energy_error(&tp, &mc);
        let (e2, _) = energy_error(&mcp, &mc);
        let fine = run(
            &stack,
            &McOptions::new(photons, 16, 7)?.with_grid(RadialGrid::geometric(0.001, 6.0, 60)?),
        );
        let enter = 1.0 - fine.specular_reflectance;
        let tot = fine.diffuse_reflectance.mean;
        let bands = [0.0, 0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0, 6.0];
        let mut s = String::new();
        for w in bands.windows(2) {
            let g = fine.radial.grid;
            let mut m = 0.0;
            for i in 0..g.bins() {
                let mid = 0.5 * (g.inner_mm(i) + g.outer_mm(i));
                if mid >= w[0] && mid < w[1] {
                    m += fine.radial.reflectance_per_mm2[i] * g.annulus_area_mm2(i);
                }
            }
            let mut mm = 0.0;
            for i in 0..g.bins() {
                let mid = 0.5 * (g.inner_mm(i) + g.outer_mm(i));
                if mid >= w[0] && mid < w[1] {
                    mm += enter * annulus_energy(&tp, g.inner_mm(i), g.outer_mm(i));
                }
            }
            s += &format!(
                " [{}-{}] mc {:.3} tab {:+.1}%",
                w[0],
                w[1],
                m / tot,
                100.0 * (mm / m - 1.0)
            );
        }
        println!(
            "C_m {c_m} b {b} C_h {c_h} {nm} nm: a1 {:.4} a2 {:.4} tau {:.2} sigma_s {:.1}/mm | table {:.2}% mc4000 {:.2}% (noise {:.2}%) first profile (table build or read included) {:.1} ms\n  {s}",
            c.epidermis.sigma_a / ss,
            c.dermis.sigma_a / ss,
            ss * skin.epidermis_thickness_mm(),
            ss,
            100.0 * e,
            100.0 * e2,
            100.0 * n,
            1e3 * dt
        );
    }
    Ok(())
}
