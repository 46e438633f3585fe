//! `skin spectrum`: layer coefficients and the diffuse reflectance of a skin over a wavelength grid,
//! as CSV on stdout; its sRGB colour under D65 on stderr; optionally a chart of the spectra.

use crate::args::{Checked, SkinArgs};
use anyhow::Context;
use clap::Args;
use multipole::Method;
use skin_optics::chromophores::{
    baseline_sigma_a, deoxyhemoglobin_sigma_a, eumelanin_sigma_a, oxyhemoglobin_sigma_a,
    pheomelanin_sigma_a,
};
use skin_optics::color::reflectance_to_xyz;
use skin_optics::echo::{Num, Text};
use skin_optics::{GridSpectrum, SkinParams, Wavelength, WavelengthGrid};
use skin_plot::{LineChart, Panel, Series, save_png};
use std::io::{self, Write};
use std::path::{Path, PathBuf};

/// The CSV header, one column per quantity with its unit.
pub const CSV_HEADER: &str = "lambda_nm,sigma_a_epidermis_per_mm,sigma_a_dermis_per_mm,sigma_s_reduced_per_mm,diffuse_reflectance";

/// Parse a wavelength in nm, [250, 1000] (clap value parser: bad values exit with code 2).
pub fn parse_wavelength_nm(s: &str) -> Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("'{}' is not a number (valid range [250, 1000] nm)", Text(s)))?;
    Wavelength::new(v)
        .map(Wavelength::nm)
        .map_err(|_| format!("{} outside [250, 1000] nm", Num(v)))
}

/// Parse a grid step in nm, [0.01, 750] (clap value parser).
pub fn parse_step_nm(s: &str) -> Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("'{}' is not a number (valid range [0.01, 750] nm)", Text(s)))?;
    if !v.is_finite() || !(WavelengthGrid::MIN_STEP_NM..=WavelengthGrid::MAX_STEP_NM).contains(&v) {
        return Err(format!("{} outside [0.01, 750] nm", Num(v)));
    }
    Ok(v)
}

/// Arguments of `skin spectrum`.
#[derive(Args, Debug, Clone)]
pub struct SpectrumArgs {
    /// The skin (preset and/or fractions).
    #[command(flatten)]
    pub skin: SkinArgs,
    /// First wavelength, nm, [250, 1000].
    #[arg(long, value_name = "NM", default_value_t = 400.0, value_parser = Checked(parse_wavelength_nm), allow_hyphen_values = true)]
    pub from: f64,
    /// Last wavelength, nm, [250, 1000] and ≥ --from (the grid stops at the last step not beyond it).
    #[arg(long, value_name = "NM", default_value_t = 700.0, value_parser = Checked(parse_wavelength_nm), allow_hyphen_values = true)]
    pub to: f64,
    /// Wavelength step, nm, [0.01, 750].
    #[arg(long, value_name = "NM", default_value_t = 10.0, value_parser = Checked(parse_step_nm), allow_hyphen_values = true)]
    pub step: f64,
    /// Diffuse reflectance model: exact (adding-doubling transport, the default: right for every
    /// skin tone) or multipole (the paper's diffusion, [DJ05]; too bright for dark skin).
    #[arg(long, value_name = "NAME", default_value_t = Method::default())]
    pub method: Method,
    /// Print to stderr, per wavelength, the treatment used and why (layer albedos, epidermis thickness
    /// in mean free paths, diffusion versus exact total).
    #[arg(long)]
    pub explain: bool,
    /// Also draw the absorption spectra (log axis, 1 nm resolution) and the reflectance to this PNG.
    #[arg(long, value_name = "FILE.png")]
    pub plot: Option<PathBuf>,
}

/// One CSV row: coefficients in mm⁻¹ and the observable diffuse reflectance (dimensionless).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpectrumRow {
    /// Wavelength, nm.
    pub lambda_nm: f64,
    /// Epidermis absorption σa, mm⁻¹ ([DJ06] eq. 1).
    pub sigma_a_epidermis_per_mm: f64,
    /// Dermis absorption σa, mm⁻¹ ([DJ06] eq. 5).
    pub sigma_a_dermis_per_mm: f64,
    /// Reduced scattering σs', mm⁻¹ ([DJ06] eq. 6; epidermis, = dermis at the default scale).
    pub sigma_s_reduced_per_mm: f64,
    /// Diffuse reflectance per unit incident flux, specular excluded, (1 − F_r(0)) R_d.
    pub diffuse_reflectance: f64,
}

/// The grid of the command: validated ends and step, `--to` not below `--from`.
pub fn grid(args: &SpectrumArgs) -> anyhow::Result<WavelengthGrid> {
    if args.to < args.from {
        anyhow::bail!(
            "--to {} nm is below --from {} nm (need --from ≤ --to, both in [250, 1000] nm)",
            args.to,
            args.from
        );
    }
    WavelengthGrid::new(args.from, args.to, args.step).context("--from/--to/--step")
}

/// The rows of the spectrum of `skin` on `grid` with the reflectance `method`.
pub fn rows(
    skin: &SkinParams,
    grid: &WavelengthGrid,
    method: Method,
) -> anyhow::Result<Vec<SpectrumRow>> {
    grid.iter()
        .map(|lambda| {
            let c = skin.coefficients(lambda);
            let r = multipole::skin::diffuse_reflectance(skin, lambda, method)
                .with_context(|| format!("diffuse reflectance at {} nm", lambda.nm()))?;
            Ok(SpectrumRow {
                lambda_nm: lambda.nm(),
                sigma_a_epidermis_per_mm: c.epidermis.sigma_a,
                sigma_a_dermis_per_mm: c.dermis.sigma_a,
                sigma_s_reduced_per_mm: c.epidermis.sigma_s_prime,
                diffuse_reflectance: r,
            })
        })
        .collect()
}

/// Wavelength for the CSV: at most 3 decimals, no trailing zeros (grid arithmetic adds noise).
fn format_nm(nm: f64) -> String {
    let s = format!("{nm:.3}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// Write the CSV (header and rows) to `out`.
pub fn write_csv(out: &mut impl Write, rows: &[SpectrumRow]) -> io::Result<()> {
    writeln!(out, "{CSV_HEADER}")?;
    for r in rows {
        writeln!(
            out,
            "{},{:.6},{:.6},{:.6},{:.6}",
            format_nm(r.lambda_nm),
            r.sigma_a_epidermis_per_mm,
            r.sigma_a_dermis_per_mm,
            r.sigma_s_reduced_per_mm,
            r.diffuse_reflectance
        )?;
    }
    Ok(())
}

/// Run `skin spectrum`.
pub fn run(args: &SpectrumArgs) -> anyhow::Result<()> {
    let skin = args.skin.to_params()?;
    let grid = grid(args)?;
    let rows = rows(&skin, &grid, args.method)?;
    if args.explain {
        for lambda in grid.iter() {
            eprintln!(
                "{}",
                multipole::skin::explain(&skin, lambda, args.method, None)
                    .with_context(|| format!("--explain at {} nm", lambda.nm()))?
            );
        }
    }
    let stdout = io::stdout();
    let mut out = io::BufWriter::new(stdout.lock());
    write_csv(&mut out, &rows)?;
    out.flush()?;

    let reflectance =
        GridSpectrum::new(grid, rows.iter().map(|r| r.diffuse_reflectance).collect())?;
    let xyz = reflectance_to_xyz(&reflectance);
    let srgb = xyz.to_linear_srgb().to_srgb();
    let hex = srgb.to_hex();
    eprintln!("srgb {hex}");
    let lab = skin_optics::lab::Lab::from_xyz(xyz);
    eprintln!("{}", lab_line(&lab));
    if grid.start_nm() > 400.0 || grid.nm(grid.len() - 1) < 700.0 {
        eprintln!(
            "note: the grid does not cover 400-700 nm; the colour holds the end reflectances beyond it"
        );
    }
    if let Some(path) = &args.plot {
        plot(path, &skin, args, &rows, &hex)?;
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}

/// Draw the absorption spectra (top, log axis, every 1 nm over [--from, --to]) and the diffuse
/// reflectance (bottom, the CSV's grid) to `path`.
fn plot(
    path: &Path,
    skin: &SkinParams,
    args: &SpectrumArgs,
    rows: &[SpectrumRow],
    hex: &str,
) -> anyhow::Result<()> {
    let fine = WavelengthGrid::new(
        args.from,
        args.to,
        1.0_f64.min(args.to - args.from).max(0.01),
    )?;
    let curve = |f: &dyn Fn(Wavelength) -> f64| -> Vec<(f64, f64)> {
        fine.iter().map(|l| (l.nm(), f(l))).collect()
    };
    let absorption = LineChart::new(
        format!(
            "Absorption: C_m = {}, β_m = {}, C_h = {}, γ = {}",
            skin.melanin(),
            skin.eumelanin_blend(),
            skin.hemoglobin(),
            skin.oxygenation()
        ),
        "wavelength (nm)",
        "coefficient (mm⁻¹)",
    )
    .log_y()
    .with_series(Series::line(
        "epidermis σa",
        curve(&|l| skin.coefficients(l).epidermis.sigma_a),
    ))
    .with_series(Series::line(
        "dermis σa",
        curve(&|l| skin.coefficients(l).dermis.sigma_a),
    ))
    .with_series(Series::dashed("eumelanin", curve(&eumelanin_sigma_a)))
    .with_series(Series::dashed("pheomelanin", curve(&pheomelanin_sigma_a)))
    .with_series(Series::dashed("oxy blood", curve(&oxyhemoglobin_sigma_a)))
    .with_series(Series::dashed(
        "deoxy blood",
        curve(&deoxyhemoglobin_sigma_a),
    ))
    .with_series(Series::dashed("baseline", curve(&baseline_sigma_a)))
    .with_series(Series::line(
        "σs' (reduced scattering)",
        curve(&|l| skin.coefficients(l).epidermis.sigma_s_prime),
    ));
    let reflectance = LineChart::new(
        format!(
            "Diffuse reflectance ({}), sRGB {hex} under D65",
            args.method
        ),
        "wavelength (nm)",
        "reflectance (per incident flux, specular excluded)",
    )
    .with_series(Series::line(
        "(1 − F_r(0)) R_d",
        rows.iter()
            .map(|r| (r.lambda_nm, r.diffuse_reflectance))
            .collect(),
    ));
    save_png(
        path,
        &[Panel::Line(absorption), Panel::Line(reflectance)],
        1000,
        1100,
    )
    .with_context(|| format!("--plot {}", path.display()))
}

/// The `lab L*=… a*=… b*=… ITA°=… (category)` line `skin spectrum` prints after the spectrum.
#[must_use]
pub fn lab_line(lab: &skin_optics::lab::Lab) -> String {
    format!(
        "lab L*={:.2} a*={:.2} b*={:.2} ITA°={:.1} ({})",
        lab.l,
        lab.a,
        lab.b,
        lab.ita_deg(),
        lab.ita_category()
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn value_parsers_name_the_range() {
        assert_eq!(parse_wavelength_nm("400"), Ok(400.0));
        assert_eq!(
            parse_wavelength_nm("100").unwrap_err(),
            "100 outside [250, 1000] nm"
        );
        assert!(
            parse_wavelength_nm("nan")
                .unwrap_err()
                .contains("[250, 1000] nm")
        );
        assert!(
            parse_wavelength_nm("x")
                .unwrap_err()
                .contains("[250, 1000] nm")
        );
        assert_eq!(parse_step_nm("0.5"), Ok(0.5));
        assert_eq!(parse_step_nm("0").unwrap_err(), "0 outside [0.01, 750] nm");
        assert!(parse_step_nm("inf").unwrap_err().contains("[0.01, 750] nm"));
    }

    #[test]
    fn csv_rows_follow_the_header() {
        let skin = SkinParams::default();
        let grid = WavelengthGrid::new(400.0, 420.0, 10.0).unwrap();
        let rows = rows(&skin, &grid, Method::Multipole).unwrap();
        let mut buf = Vec::new();
        write_csv(&mut buf, &rows).unwrap();
        let text = String::from_utf8(buf).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[0], CSV_HEADER);
        assert_eq!(lines.len(), 4);
        let first: Vec<f64> = lines[1].split(',').map(|f| f.parse().unwrap()).collect();
        let c = skin.coefficients(Wavelength::new(400.0).unwrap());
        assert_eq!(first[0], 400.0);
        assert!((first[1] - c.epidermis.sigma_a).abs() < 1e-6);
        assert!((first[2] - c.dermis.sigma_a).abs() < 1e-6);
        assert!((first[3] - c.epidermis.sigma_s_prime).abs() < 1e-6);
        assert!(first[4] > 0.0 && first[4] < 1.0);
    }

    #[test]
    fn wavelengths_print_without_grid_noise() {
        assert_eq!(format_nm(400.0), "400");
        assert_eq!(format_nm(400.300_000_000_000_07), "400.3");
        assert_eq!(format_nm(412.25), "412.25");
    }
}
