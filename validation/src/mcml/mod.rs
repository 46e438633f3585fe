//! MCML 1.2 ([WJZ95] Wang, Jacques & Zheng 1995, the original C program) as an independent check of
//! the layered Monte Carlo (`multipole::exact::montecarlo`, docs/physics.md §11): the cases compared, their
//! MCML input (`.mci`) written from the same [`LayeredMedium`] our code builds, MCML's ASCII output
//! (`.mco`) read back, and the reference data committed under `validation/data/mcml/`.
//!
//! MCML works in cm and cm⁻¹, scores R_d(r) in annuli of width dr from r = 0 with the last annulus
//! collecting every photon escaping beyond the grid (`RecordR` in `mcmlgo.c`: `if (ir > nr-1) ir =
//! nr-1`), and divides each annulus' weight by 2π(i + ½)dr² (`ScaleRdTt` in `mcmlio.c`), which is
//! the annulus' exact area π((i + 1)² − i²)dr². [`mcml_binned`] puts our run on that footing.
//! It needs finite layers: a semi-infinite layer is written [`HALF_SPACE_DEPTH_MM`] thick.
//!
//! Each grid constant is MCML's input, so none can be derived from another.

mod compare;
mod output;
mod process;
mod reference;

pub use compare::{Comparison, GROUP_EDGES, Row, compare, groups};
pub use output::{McmlOutput, parse_mco};
pub use process::{McmlProcess, run_mcml, thread_cpu_seconds};
pub use reference::ReferenceData;

use crate::montecarlo::{DEFAULT_G, Layer, LayeredMedium, McResult, RadialGrid};
use multipole::MultipoleError;
use skin_optics::{Preset, SkinParams, Wavelength};
use std::fmt::Write as _;

/// Errors of the MCML bridge: a malformed `.mco` or reference file, or a bad case.
#[derive(Debug, thiserror::Error)]
pub enum McmlError {
    /// A section or value MCML writes is missing or unreadable.
    #[error("MCML output: {0}")]
    Output(String),
    /// The committed reference data is malformed.
    #[error("MCML reference data, line {line}: {what}")]
    Reference {
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        what: String,
    },
    /// A layer stack that cannot be built.
    #[error(transparent)]
    Stack(#[from] MultipoleError),
}

/// Depth standing in for a semi-infinite layer, mm: 100 mm is ≥ 17 diffusion lengths 1/μ_eff of
/// every case's deepest layer (μ_eff = √(3σa(σa + σs')) ≥ 0.17 mm⁻¹), so less than e⁻¹⁷ ≈ 4·10⁻⁸ of
/// the light reaches the bottom; the transmittance in the data confirms it.
pub const HALF_SPACE_DEPTH_MM: f64 = 100.0;

/// Width of MCML's radial annuli in the reference runs, mm.
pub const DR_MM: f64 = 0.01;
/// Number of MCML annuli (the grid reaches 10 mm; the last one collects everything beyond 9.99 mm).
pub const NR: usize = 1000;
/// Depth step of MCML's absorption grid, mm: 0.05 mm puts the 0.25 mm epidermis in 5 whole bins,
/// so MCML's per-layer absorption (`A_l`, assigned by bin centre) is exact.
pub const DZ_MM: f64 = 0.05;
/// Depth bins of MCML's absorption grid (to 10 mm; deeper absorption lands in the last bin).
pub const NZ: usize = 200;

/// A compared case: a name (the data file's stem) and the layers, with finite thicknesses.
#[derive(Debug, Clone, PartialEq)]
pub struct Case {
    /// File stem, e.g. `light-550`.
    pub name: &'static str,
    /// What it is, for tables.
    pub description: &'static str,
    /// The layers as MCML and our Monte Carlo both trace them.
    pub stack: LayeredMedium,
}

/// The reference cases: [DJ06] skin (`LayeredMedium::skin`, g = 0.9, n = 1.4 in air) for the light
/// preset at 450/550/650 nm, the dark preset at 450/650 nm and the darkest skins of the parameter box
/// in the blue ([`DARK_BLUE_CASES`]), and a homogeneous half-space (σa 0.01, σs' 1 mm⁻¹, g 0.9,
/// n 1.4), each dermis or half-space [`HALF_SPACE_DEPTH_MM`] deep.
pub fn cases() -> Result<Vec<Case>, McmlError> {
    let stack = |skin: &SkinParams, nm| -> Result<LayeredMedium, McmlError> {
        let lambda = Wavelength::new(nm).map_err(|e| McmlError::Output(e.to_string()))?;
        Ok(finite(&LayeredMedium::skin(skin, lambda, DEFAULT_G)?)?)
    };
    let skin = |preset, nm| stack(&SkinParams::preset(preset), nm);
    let half_space = LayeredMedium::new(
        vec![Layer::from_reduced(0.01, 1.0, DEFAULT_G, 1.4, None)?],
        1.0,
        1.0,
    )?;
    let skins = [
        ("light-450", "light skin, 450 nm", Preset::Light, 450.0),
        ("light-550", "light skin, 550 nm", Preset::Light, 550.0),
        ("light-650", "light skin, 650 nm", Preset::Light, 650.0),
        ("dark-450", "dark skin, 450 nm", Preset::Dark, 450.0),
        ("dark-650", "dark skin, 650 nm", Preset::Dark, 650.0),
    ];
    let mut cases = skins
        .into_iter()
        .map(|(name, description, preset, nm)| {
            Ok(Case {
                name,
                description,
                stack: skin(preset, nm)?,
            })
        })
        .collect::<Result<Vec<_>, McmlError>>()?;
    for c in DARK_BLUE_CASES {
        let params = SkinParams::new(c.c_m, c.beta_m, c.c_h, 0.25)
            .map_err(|e| McmlError::Output(e.to_string()))?;
        cases.push(Case {
            name: c.name,
            description: c.description,
            stack: stack(&params, c.nm)?,
        });
    }
    cases.push(Case {
        name: "half-space",
        description: "half-space σa 0.01, σs' 1 mm⁻¹",
        stack: finite(&half_space)?,
    });
    Ok(cases)
}

/// A dark skin in the blue of [`DARK_BLUE_CASES`]: default epidermis 0.25 mm, ρ_s 0.25.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DarkBlueCase {
    /// File stem.
    pub name: &'static str,
    /// What it is, for tables.
    pub description: &'static str,
    /// Melanin fraction C_m.
    pub c_m: f64,
    /// Eumelanin share β_m.
    pub beta_m: f64,
    /// Blood fraction C_h.
    pub c_h: f64,
    /// Wavelength, nm.
    pub nm: f64,
}

/// Dark skins in the blue, where the epidermis absorbs a quarter to half of σs.
pub const DARK_BLUE_CASES: &[DarkBlueCase] = &[
    DarkBlueCase {
        name: "cm50-400",
        description: "C_m 0.5, β_m 0.9, C_h 0.07, 400 nm",
        c_m: 0.5,
        beta_m: 0.9,
        c_h: 0.07,
        nm: 400.0,
    },
    DarkBlueCase {
        name: "cm50-450",
        description: "C_m 0.5, β_m 0.9, C_h 0.07, 450 nm",
        c_m: 0.5,
        beta_m: 0.9,
        c_h: 0.07,
        nm: 450.0,
    },
    DarkBlueCase {
        name: "cm25-400",
        description: "C_m 0.25, β_m 0.9, C_h 0.04, 400 nm",
        c_m: 0.25,
        beta_m: 0.9,
        c_h: 0.04,
        nm: 400.0,
    },
    DarkBlueCase {
        name: "cm25-500",
        description: "C_m 0.25, β_m 0.9, C_h 0.04, 500 nm",
        c_m: 0.25,
        beta_m: 0.9,
        c_h: 0.04,
        nm: 500.0,
    },
];

/// The case named `name`.
pub fn case(name: &str) -> Result<Case, McmlError> {
    cases()?
        .into_iter()
        .find(|c| c.name == name)
        .ok_or_else(|| McmlError::Output(format!("no case named '{name}'")))
}

/// `stack` with a semi-infinite last layer made [`HALF_SPACE_DEPTH_MM`] thick (MCML has no
/// semi-infinite layers).
pub fn finite(stack: &LayeredMedium) -> Result<LayeredMedium, MultipoleError> {
    let layers = stack
        .layers()
        .iter()
        .map(|l| {
            Layer::slab(
                l.sigma_a(),
                l.sigma_s(),
                l.g(),
                l.n(),
                l.thickness_mm().unwrap_or(HALF_SPACE_DEPTH_MM),
            )
        })
        .collect::<Result<Vec<_>, _>>()?;
    LayeredMedium::new(layers, stack.n_above(), stack.n_below())
}

/// One run of an `.mci` file: the output file MCML writes and the photons it traces.
#[derive(Debug, Clone, PartialEq)]
pub struct McmlRun {
    /// Output file name (relative to MCML's working directory).
    pub output: String,
    /// Photons traced.
    pub photons: u64,
}

/// MCML's input file for `runs` of `stack` on the reference grid ([`DR_MM`] × [`NR`] annuli,
/// [`DZ_MM`] × [`NZ`] depths, one exit angle), with `comment` lines (ASCII: MCML rejects other
/// bytes) at the top. Lengths are written in cm and coefficients in cm⁻¹ (MCML's units), shortest
/// round-trip decimals.
pub fn mci(stack: &LayeredMedium, runs: &[McmlRun], comment: &str) -> Result<String, McmlError> {
    if !comment.is_ascii() {
        return Err(McmlError::Output(format!(
            "MCML input comments must be ASCII: '{comment}'"
        )));
    }
    let mut s = String::new();
    for line in comment.lines() {
        let _ = writeln!(s, "# {line}");
    }
    let _ = writeln!(s, "1.0\t# file version\n{}\t# number of runs", runs.len());
    for run in runs {
        let _ = writeln!(
            s,
            "\n{} A\t# output file, ASCII\n{}\t# photons\n{:e} {:e}\t# dz, dr (cm)\n{NZ} {NR} 1\t# dz, dr, da bins",
            run.output,
            run.photons,
            DZ_MM / 10.0,
            DR_MM / 10.0
        );
        let _ = writeln!(
            s,
            "{}\t# layers\n{:e}\t# n above\n# n mua(1/cm) mus(1/cm) g d(cm)",
            stack.layers().len(),
            stack.n_above()
        );
        for l in stack.layers() {
            let d = l.thickness_mm().ok_or_else(|| {
                McmlError::Output("MCML needs finite layers (see `finite`)".into())
            })?;
            let _ = writeln!(
                s,
                "{:e} {:e} {:e} {:e} {:e}",
                l.n(),
                l.sigma_a() * 10.0,
                l.sigma_s() * 10.0,
                l.g(),
                d / 10.0
            );
        }
        let _ = writeln!(s, "{:e}\t# n below", stack.n_below());
    }
    Ok(s)
}

/// Our run `r` binned as MCML bins it: R_d(r) per annulus of the uniform grid `r.radial.grid`
/// (mm⁻², per incident photon), except that the last annulus also holds the weight escaping beyond
/// the grid, divided by that annulus' area. `None` if the grid is not uniform from r = 0.
#[must_use]
pub fn mcml_binned(r: &McResult) -> Option<Vec<f64>> {
    let g: RadialGrid = r.radial.grid;
    let n = g.bins();
    let dr = g.outer_mm(0);
    let uniform = (0..n).all(|i| (g.inner_mm(i) - i as f64 * dr).abs() <= 1e-9 * dr * n as f64);
    if !uniform {
        return None;
    }
    let mut v = r.radial.reflectance_per_mm2.clone();
    v[n - 1] += r.radial.beyond_grid / g.annulus_area_mm2(n - 1);
    Some(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cases_are_finite_and_written_in_cm() {
        let cases = cases().unwrap();
        assert_eq!(cases.len(), 10);
        for c in &cases {
            let last = c.stack.layers().last().unwrap();
            assert_eq!(last.thickness_mm(), Some(HALF_SPACE_DEPTH_MM));
        }
        let runs = [McmlRun {
            output: "x.mco".into(),
            photons: 10,
        }];
        let light = case("light-550").unwrap();
        let text = mci(&light.stack, &runs, "a comment").unwrap();
        // The epidermis, 0.25 mm = 2.5e-2 cm thick, σs 60.8 mm⁻¹ = 608 cm⁻¹; the dermis 10 cm.
        assert!(text.contains(" 9e-1 2.5e-2\n"), "{text}");
        assert!(text.contains(" 9e-1 1e1\n"), "{text}");
        assert!(text.contains("x.mco A"));
        assert!(text.contains("5e-3 1e-3\t# dz, dr (cm)"), "{text}");
        assert!(mci(&light.stack, &runs, "σ").is_err());
        assert!(case("nonsense").is_err());
    }
}
