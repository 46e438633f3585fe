//! MCML 1.2 input (`.mci`, [WJZ95]): one run per wavelength with our layers in MCML's units (cm, cm⁻¹;
//! μs not reduced), and a parser of that format so that the file can be read back and run through our
//! own layered Monte Carlo (docs/physics.md §11, §14).
//!
//! MCML needs every layer finite: the dermis gets [`ExportOptions::dermis_thickness_mm`]. Its records:
//! file version; number of runs; then per run the output name and format, photons, dz dr (cm),
//! nz nr na, number of layers, n above, one `n mua mus g d` line per layer, n below. `#` starts a
//! comment; blank lines are skipped.

use crate::ExportOptions;
use crate::error::ExportError;
use crate::spectral::{LayerOptics, SpectralSkin, to_stack};
use multipole::LayeredMedium;
use std::fmt::Write;

/// Millimetres per centimetre.
const MM_PER_CM: f64 = 10.0;
/// Radial and depth bin of the written runs, cm (10 µm: resolves the epidermis).
pub const BIN_CM: f64 = 0.001;
/// Radial bins (out to 5 mm) and depth bins (1 mm) of the written runs.
pub const BINS_R: usize = 500;
/// Depth bins.
pub const BINS_Z: usize = 100;

/// `s` in ASCII, which is all MCML 1.2 reads (it stops at any other byte): Greek letters and unit
/// superscripts spelled out, anything else left as `?`.
#[must_use]
pub fn ascii(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for ch in s.chars() {
        match ch {
            c if c.is_ascii() => out.push(c),
            'μ' => out.push_str("mu"),
            'σ' => out.push_str("sigma"),
            'β' => out.push_str("beta"),
            'ρ' => out.push_str("rho"),
            'η' => out.push_str("eta"),
            '⁻' => out.push_str("^-"),
            '¹' => out.push('1'),
            '²' => out.push('2'),
            '–' | '−' | '‒' => out.push('-'),
            '×' => out.push('x'),
            '≤' => out.push_str("<="),
            '§' => out.push_str("section "),
            _ => out.push('?'),
        }
    }
    out
}

/// Width of a wrapped comment line, bytes (MCML's `fgets` reads 254 at a time).
pub const COMMENT_WIDTH: usize = 100;

/// `s` broken at spaces into lines of at most `width` bytes (a longer word keeps its own line).
#[must_use]
pub fn wrap(s: &str, width: usize) -> Vec<String> {
    let mut lines = vec![String::new()];
    for word in s.split(' ') {
        let last = lines.last_mut().expect("one line at least");
        if !last.is_empty() && last.len() + 1 + word.len() > width {
            lines.push(word.to_string());
        } else {
            if !last.is_empty() {
                last.push(' ');
            }
            last.push_str(word);
        }
    }
    lines
}

/// One MCML run as written in the file.
#[derive(Debug, Clone, PartialEq)]
pub struct MciRun {
    /// Output file name.
    pub output: String,
    /// Photons.
    pub photons: u64,
    /// Depth and radial bin widths, cm.
    pub dz_cm: f64,
    /// Radial bin width, cm.
    pub dr_cm: f64,
    /// Bins in z, r and angle.
    pub bins: [usize; 3],
    /// Index above the top layer.
    pub n_above: f64,
    /// Layers top first: (n, μa cm⁻¹, μs cm⁻¹, g, d cm).
    pub layers: Vec<[f64; 5]>,
    /// Index below the last layer.
    pub n_below: f64,
}

impl MciRun {
    /// The run's layers as our layered medium (mm, mm⁻¹).
    pub fn to_stack(&self) -> Result<LayeredMedium, ExportError> {
        let layers: Vec<LayerOptics> = self
            .layers
            .iter()
            .map(|&[n, mua, mus, g, d]| LayerOptics {
                sigma_a_per_mm: mua / MM_PER_CM,
                sigma_s_per_mm: mus / MM_PER_CM,
                g,
                n,
                thickness_mm: Some(d * MM_PER_CM),
            })
            .collect();
        to_stack(&layers, self.n_above, self.n_below)
    }
}

/// The `.mci` text (one run per row of `spectral`) and its notes.
pub fn write(
    spectral: &SpectralSkin,
    opts: &ExportOptions,
) -> Result<(String, Vec<String>), ExportError> {
    let mut x = String::new();
    let _ = writeln!(x, "1.0\t# file version");
    let _ = writeln!(x, "{}\t# number of runs", spectral.rows.len());
    for row in &spectral.rows {
        let _ = writeln!(x, "\n#### run: {} nm", row.lambda_nm);
        let _ = writeln!(
            x,
            "skin_{}nm.mco\tA\t# output file name, ASCII",
            row.lambda_nm
        );
        let _ = writeln!(x, "{}\t# photons", opts.photons);
        let _ = writeln!(x, "{BIN_CM}\t{BIN_CM}\t# dz, dr (cm)");
        let _ = writeln!(x, "{BINS_Z}\t{BINS_R}\t1\t# number of dz, dr, da");
        let _ = writeln!(x, "{}\t# number of layers", row.layers.len());
        let _ = writeln!(x, "#n\tmua\tmus\tg\td (cm⁻¹, cm)");
        let _ = writeln!(x, "{}\t# n above", spectral.n_above);
        for (i, l) in row.layers.iter().enumerate() {
            let d_mm = l.thickness_mm.unwrap_or(opts.dermis_thickness_mm);
            let _ = writeln!(
                x,
                "{}\t{:.6e}\t{:.6e}\t{}\t{:.6e}\t# layer {}",
                l.n,
                l.sigma_a_per_mm * MM_PER_CM,
                l.sigma_s_per_mm * MM_PER_CM,
                l.g,
                d_mm / MM_PER_CM,
                i + 1
            );
        }
        let below = row.layers.last().map_or(1.0, |l| l.n);
        let _ = writeln!(x, "{below}\t# n below (index-matched to the finite dermis)");
    }
    let notes = vec![
        format!(
            "units: MCML's: lengths cm, μa and μs cm⁻¹ (μs not reduced), g, n; {} photons per run; bins dz = dr = {BIN_CM} cm, {BINS_Z} × {BINS_R}",
            opts.photons
        ),
        format!(
            "conventions: one run per wavelength ({} runs), air above, the dermis {} mm thick (MCML needs finite layers) with a matched index below so nothing returns from its bottom",
            spectral.rows.len(),
            opts.dermis_thickness_mm
        ),
        "accuracy: nothing lost by construction (our layers); MCML's Rd is per incident photon with the specular Rsp apart: compare with `skin spectrum`'s diffuse_reflectance column".to_string(),
    ];
    Ok((x, notes))
}

/// Parse an `.mci` text into its runs.
pub fn parse(text: &str) -> Result<Vec<MciRun>, ExportError> {
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.split('#').next().unwrap_or("").trim()))
        .filter(|(_, l)| !l.is_empty());
    let mut next = |what: &str| {
        lines.next().ok_or_else(|| ExportError::Mci {
            line: text.lines().count(),
            message: format!("file ends before {what}"),
        })
    };
    fn numbers(line: usize, l: &str, n: usize, what: &str) -> Result<Vec<f64>, ExportError> {
        let v: Vec<f64> = l
            .split_whitespace()
            .take(n)
            .map(str::parse)
            .collect::<Result<_, _>>()
            .map_err(|_| ExportError::Mci {
                line,
                message: format!("expected {what}, found '{l}'"),
            })?;
        if v.len() < n || v.iter().any(|x| !x.is_finite()) {
            return Err(ExportError::Mci {
                line,
                message: format!("expected {what}, found '{l}'"),
            });
        }
        Ok(v)
    }
    let (line, l) = next("the file version")?;
    numbers(line, l, 1, "the file version")?;
    let (line, l) = next("the number of runs")?;
    let runs = numbers(line, l, 1, "the number of runs (1-32767)")?[0];
    if !(1.0..=32767.0).contains(&runs) || runs.fract() != 0.0 {
        return Err(ExportError::Mci {
            line,
            message: format!("number of runs {runs} outside [1, 32767]"),
        });
    }
    let mut out = Vec::new();
    for _ in 0..runs as usize {
        let (line, l) = next("the output file name")?;
        let output = l.split_whitespace().next().unwrap_or("").to_string();
        if !l
            .split_whitespace()
            .nth(1)
            .is_some_and(|f| f == "A" || f == "a")
        {
            return Err(ExportError::Mci {
                line,
                message: format!("expected 'NAME A' (ASCII output), found '{l}'"),
            });
        }
        let (line, l) = next("the photon count")?;
        let photons = numbers(line, l, 1, "the photon count")?[0];
        let (line, l) = next("dz dr")?;
        let d = numbers(line, l, 2, "dz dr (cm)")?;
        let (line, l) = next("nz nr na")?;
        let b = numbers(line, l, 3, "nz nr na")?;
        let (line, l) = next("the number of layers")?;
        let count = numbers(line, l, 1, "the number of layers")?[0];
        if !(1.0..=100.0).contains(&count) {
            return Err(ExportError::Mci {
                line,
                message: format!("number of layers {count} outside [1, 100]"),
            });
        }
        let (line, l) = next("n above")?;
        let n_above = numbers(line, l, 1, "n above")?[0];
        let mut layers = Vec::new();
        for _ in 0..count as usize {
            let (line, l) = next("a layer")?;
            let v = numbers(line, l, 5, "a layer 'n mua mus g d'")?;
            layers.push([v[0], v[1], v[2], v[3], v[4]]);
        }
        let (line, l) = next("n below")?;
        let n_below = numbers(line, l, 1, "n below")?[0];
        out.push(MciRun {
            output,
            photons: photons as u64,
            dz_cm: d[0],
            dr_cm: d[1],
            bins: [b[0] as usize, b[1] as usize, b[2] as usize],
            n_above,
            layers,
            n_below,
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_mcml_sample_layout_and_names_bad_lines() {
        let text = "1.0 # version\n1\n\nout.mco A\n1000\n0.01 0.01\n40 50 1\n2\n1\n1.37 1 100 0.9 0.1\n1.37 2 10 0.0 0.2\n1\n";
        let runs = parse(text).unwrap();
        assert_eq!(runs.len(), 1);
        assert_eq!(runs[0].layers[1], [1.37, 2.0, 10.0, 0.0, 0.2]);
        let stack = runs[0].to_stack().unwrap();
        // 1 cm⁻¹ = 0.1 mm⁻¹, 0.1 cm = 1 mm.
        assert!((stack.layers()[0].sigma_a() - 0.1).abs() < 1e-12);
        assert_eq!(stack.layers()[0].thickness_mm(), Some(1.0));
        let bad = text.replace("1.37 2 10 0.0 0.2", "1.37 2 ten 0.0 0.2");
        let e = parse(&bad).unwrap_err().to_string();
        assert!(e.contains("line 11") && e.contains("n mua mus g d"), "{e}");
        assert!(
            parse("1.0\n")
                .unwrap_err()
                .to_string()
                .contains("number of runs")
        );
    }
}
