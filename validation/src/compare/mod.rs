//! The comparison behind `skin-validate`: diffusion (`multipole`) against the Monte Carlo reference.
//!
//! Four studies, each written as a PNG chart plus the CSV behind it, and a markdown summary of the
//! worst errors (`summary.md`):
//! 1. [`spectra`]: observable diffuse reflectance over 400–700 nm per preset, multipole vs MC;
//! 2. [`profiles`]: radial profiles at 450/550/650 nm for the light preset (log axis);
//! 3. [`stability`]: diffusion's relative error over reduced albedo × slab thickness;
//! 4. [`knobs`]: time against error for every knob of `multipole` and the MC photon count;
//! 5. [`exact`]: `Method::Exact` beside `Method::Multipole` against MC, totals over C_m and profiles.
//!
//! [`table_knobs`] (`skin-validate table-knobs`, run alone: it builds a dozen shape tables) charts
//! error against cost for every knob of the exact profile's shape table.
//!
//! The observable compared is the diffuse reflectance per incident photon at normal incidence,
//! specular excluded: the MC's R_d against (1 − F_r(0)) R_d of diffusion
//! (`multipole::skin::diffuse_reflectance`).

pub mod exact;
pub mod knobs;
pub mod profiles;
pub mod render_study;
pub mod spectra;
pub mod stability;
pub mod table_knobs;

use crate::montecarlo::{self, LayeredMedium, McOptions, McResult};
use anyhow::Context;
use indicatif::{ProgressBar, ProgressStyle};
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

/// How much work each study does: `quick` (under two minutes) or full.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    /// Wavelength step of the spectra, nm.
    pub spectrum_step_nm: f64,
    /// Photons per MC run of the spectra.
    pub spectrum_photons: u64,
    /// Photons per MC run of the radial profiles.
    pub profile_photons: u64,
    /// Least photons per MC run of the exact-versus-multipole spectra.
    pub exact_photons: u64,
    /// Escaping photons wanted per MC run of those spectra: dark skin (R_d ≈ 0.005) traces up to
    /// 100 × `exact_photons` to keep the relative noise about the same for every skin tone.
    pub exact_escapes: u64,
    /// Cells per axis of the stability map.
    pub stability_cells: usize,
    /// Photons per cell of the stability map.
    pub stability_photons: u64,
    /// Largest photon count of the speed/accuracy study.
    pub knob_max_photons: u64,
    /// Seed of every MC run (each run uses it; runs differ in their medium).
    pub seed: u64,
}

impl Settings {
    /// The quick settings (about a minute on 2 cores) or the full ones.
    #[must_use]
    pub fn new(quick: bool) -> Self {
        if quick {
            Self {
                spectrum_step_nm: 100.0,
                spectrum_photons: 10_000,
                profile_photons: 40_000,
                exact_photons: 100_000,
                exact_escapes: 10_000,
                stability_cells: 6,
                stability_photons: 3_000,
                knob_max_photons: 30_000,
                seed: 1,
            }
        } else {
            Self {
                spectrum_step_nm: 10.0,
                spectrum_photons: 50_000,
                profile_photons: 1_000_000,
                exact_photons: 300_000,
                exact_escapes: 150_000,
                stability_cells: 12,
                stability_photons: 20_000,
                knob_max_photons: 1_000_000,
                seed: 1,
            }
        }
    }
}

/// Worst errors of each study, for the summary table.
#[derive(Debug, Clone, Default)]
pub struct Summary {
    /// Table rows: (study, case, worst error, where).
    pub rows: Vec<[String; 4]>,
}

impl Summary {
    fn push(&mut self, study: &str, case: &str, error: String, location: String) {
        self.rows.push([study.into(), case.into(), error, location]);
    }

    /// The markdown table.
    #[must_use]
    pub fn to_markdown(&self, command: &str, seconds: f64) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "Diffusion (multipole) versus Monte Carlo, observable diffuse reflectance (specular excluded)."
        );
        let _ = writeln!(
            s,
            "Command: `{command}` ({seconds:.0} s on this machine).\n"
        );
        let _ = writeln!(s, "| study | case | worst error | where |");
        let _ = writeln!(s, "|---|---|---|---|");
        for r in &self.rows {
            let _ = writeln!(s, "| {} | {} | {} | {} |", r[0], r[1], r[2], r[3]);
        }
        s
    }
}

/// A progress bar over `total` units of work, on stderr.
pub(crate) fn progress(total: u64, what: &str) -> ProgressBar {
    let bar = ProgressBar::new(total);
    if let Ok(style) = ProgressStyle::with_template(&format!(
        "{{elapsed_precise}} [{{bar:30}}] {{pos}}/{{len}} {what} (eta {{eta}})"
    )) {
        bar.set_style(style.progress_chars("=> "));
    }
    bar
}

/// One MC run, timed (seconds).
pub(crate) fn timed_mc(stack: &LayeredMedium, opts: &McOptions) -> (McResult, f64) {
    let t = Instant::now();
    let r = montecarlo::run(stack, opts);
    (r, t.elapsed().as_secs_f64())
}

/// CSV text written atomically.
pub(crate) fn write_csv(path: &Path, header: &str, rows: &[String]) -> anyhow::Result<()> {
    let mut s = String::with_capacity(64 * (rows.len() + 1));
    s.push_str(header);
    s.push('\n');
    for r in rows {
        s.push_str(r);
        s.push('\n');
    }
    skin_io::atomic::write_bytes(path, s.as_bytes())
        .with_context(|| format!("writing {}", path.display()))
}

/// A study's two outputs: `out/{name}.csv` (`header`, then `rows`) and the chart `out/{name}.png`
/// of `panels`, `size` = (width, height) pixels.
pub(crate) fn write_study(
    out: &Path,
    name: &str,
    (header, rows): (&str, &[String]),
    panels: &[skin_plot::Panel],
    (width, height): (u32, u32),
) -> anyhow::Result<()> {
    write_csv(&out.join(format!("{name}.csv")), header, rows)?;
    skin_plot::save_png(&out.join(format!("{name}.png")), panels, width, height)
        .with_context(|| format!("writing {name}.png"))
}

/// One study: writes its charts and CSV into the folder and its worst errors into the summary.
type Study = fn(&Settings, &Path, &mut Summary) -> anyhow::Result<()>;

/// Run only study 5 ([`exact`]) into `out` and write `summary.md`; returns the summary (Markdown).
pub fn run_exact(quick: bool, out: &Path) -> anyhow::Result<String> {
    run_studies(quick, out, " exact", &[exact::run])
}

/// Run all five studies into `out` and write `summary.md`; returns the summary (Markdown).
pub fn run_comparison(quick: bool, out: &Path) -> anyhow::Result<String> {
    run_studies(
        quick,
        out,
        "",
        &[
            spectra::run,
            profiles::run,
            stability::run,
            knobs::run,
            exact::run,
        ],
    )
}

/// Run `studies` in order into `out`, then write `summary.md` with the command that reproduces it
/// (`subcommand` is what follows `skin-validate --`, with its leading space).
fn run_studies(
    quick: bool,
    out: &Path,
    subcommand: &str,
    studies: &[Study],
) -> anyhow::Result<String> {
    let settings = Settings::new(quick);
    let start = Instant::now();
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let mut summary = Summary::default();
    for study in studies {
        study(&settings, out, &mut summary)?;
    }
    let seconds = start.elapsed().as_secs_f64();
    let command = format!(
        "cargo run --release -p validation --bin skin-validate --{subcommand}{} --out {}",
        if quick { " --quick" } else { "" },
        out.display()
    );
    let md = summary.to_markdown(&command, seconds);
    skin_io::atomic::write_bytes(&out.join("summary.md"), md.as_bytes())?;
    log::info!("skin-validate: wrote {} in {seconds:.1} s", out.display());
    Ok(md)
}
