//! `skin-validate engines`: each installed engine run on the files `skin export` writes, against our
//! exact numbers (docs/physics.md §14). The engines are Python packages driven by the scripts in
//! `validation/engines/`, run by the Python interpreter given; an engine that cannot be imported is
//! skipped with a note. Scenes:
//! - **MaterialX**: the OpenPBR document in lin_rec709 and in acescg, checked by MaterialX's own
//!   `validate()` and nodedefs; the acescg radii carried through MaterialX's own colour transform
//!   to lin_rec709 against the lin_rec709 file's;
//! - **Mitsuba 3**: the flat slab under a uniform sky of radiance 1 at normal view (`--scene`), in
//!   the rgb variant (per channel: F(0) + the RGB of `skin spectrum`'s diffuse reflectance) and the
//!   mono variant at 550 nm (F(0) + the diffuse reflectance there);
//! - **MCX** (pmcxcl, MCX on OpenCL): the exported input at 550 nm, its detected weights per photon
//!   entering against our adding-doubling total per photon entering (the file's normalisation);
//! - **Blender Cycles** (bpy): the `blender` script's Principled BSDF (Random Walk and Random Walk
//!   (Skin)) on the flat slab at normal view and over a sphere, both under a uniform white sky, its
//!   subsurface part (the render minus the same render with Base Color 0) against the RGB of
//!   `skin spectrum`'s diffuse reflectance, and the sphere's also against our volumetric walk on the
//!   same sphere (`sphere`), the reference a sphere under a sky has; and its volumetric slab
//!   (`volume_slab()`) against F(0) + that reflectance.

pub mod sphere;

use anyhow::{Context, bail};
use skin_export::mitsuba::Variant;
use skin_export::{ColourSpace, ExportOptions, Format, export};
use skin_optics::color::reflectance_to_xyz;
use skin_optics::{GridSpectrum, Preset, SkinParams, WavelengthGrid};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The folder of the driver scripts in this repository.
pub const SCRIPTS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/engines");

/// The knobs of a run.
#[derive(Debug, Clone)]
pub struct EngineOptions {
    /// The Python interpreter that has the engines installed.
    pub python: PathBuf,
    /// Folder of the driver scripts.
    pub scripts: PathBuf,
    /// Output folder (CSV, PNG, the exported files).
    pub out: PathBuf,
    /// Samples per pixel of the Mitsuba renders (16 × 16 pixels each).
    pub spp: u32,
    /// Samples per pixel of the Cycles renders.
    pub cycles_spp: u32,
    /// Samples per pixel of our volumetric sphere, the Cycles sphere's reference.
    pub sphere_spp: u32,
    /// Photons of each MCX run.
    pub mcx_photons: u64,
    /// Run only the engines whose Python module is listed (empty: every engine).
    pub only: Vec<String>,
    /// A library preloaded into the MCX driver (pocl's kernel compiler on some systems needs the
    /// system libstdc++ ahead of the one Python loads).
    pub mcx_preload: Option<PathBuf>,
}

/// One comparison: an engine's number against ours.
#[derive(Debug, Clone)]
pub struct Row {
    /// Engine and its version.
    pub engine: String,
    /// Skin preset.
    pub preset: &'static str,
    /// What is compared (with its variant or wavelength).
    pub quantity: String,
    /// Channel (R, G, B, or the wavelength).
    pub channel: String,
    /// Our exact value.
    pub ours: f64,
    /// The engine's.
    pub engine_value: f64,
    /// The engine's standard error (0 where it is deterministic).
    pub engine_stderr: f64,
}

impl Row {
    /// One row per RGB channel: `ours[c]` against the engine's `value[c]` ± `stderr[c]`.
    fn rgb(
        engine: &str,
        preset: &'static str,
        quantity: &str,
        ours: [f64; 3],
        value: &[f64],
        stderr: [f64; 3],
    ) -> impl Iterator<Item = Row> {
        (0..3).map(move |c| Row {
            engine: engine.to_string(),
            preset,
            quantity: quantity.to_string(),
            channel: ["R", "G", "B"][c].into(),
            ours: ours[c],
            engine_value: value[c],
            engine_stderr: stderr[c],
        })
    }
}

impl Row {
    /// (engine − ours) / ours.
    #[must_use]
    pub fn rel_error(&self) -> f64 {
        (self.engine_value - self.ours) / self.ours
    }
}

/// Run a driver script; its stdout's last line parsed as JSON.
fn driver(opts: &EngineOptions, script: &str, args: &[&str]) -> anyhow::Result<serde_json::Value> {
    driver_with(opts, script, args, None)
}

/// [`driver`] with `LD_PRELOAD` set to `preload` when given.
fn driver_with(
    opts: &EngineOptions,
    script: &str,
    args: &[&str],
    preload: Option<&Path>,
) -> anyhow::Result<serde_json::Value> {
    let mut cmd = Command::new(&opts.python);
    cmd.arg(opts.scripts.join(script)).args(args);
    if let Some(p) = preload {
        cmd.env("LD_PRELOAD", p);
    }
    let out = cmd
        .output()
        .with_context(|| format!("running {} {script}", opts.python.display()))?;
    if !out.status.success() {
        bail!(
            "{script} failed: {}",
            String::from_utf8_lossy(&out.stderr)
                .lines()
                .last()
                .unwrap_or("")
        );
    }
    let stdout = String::from_utf8_lossy(&out.stdout);
    let line = stdout.lines().last().context("no output")?;
    Ok(serde_json::from_str(line)?)
}

/// Whether `module` imports in the interpreter.
fn importable(opts: &EngineOptions, module: &str) -> bool {
    Command::new(&opts.python)
        .args(["-c", &format!("import {module}")])
        .output()
        .is_ok_and(|o| o.status.success())
}

fn numbers(v: &serde_json::Value) -> Vec<f64> {
    v.as_array()
        .map(|a| a.iter().filter_map(serde_json::Value::as_f64).collect())
        .unwrap_or_default()
}

/// Export `format` of `skin` to `path`.
fn write_export(
    skin: &SkinParams,
    format: Format,
    opts: &ExportOptions,
    path: &Path,
) -> anyhow::Result<()> {
    let e = export(skin, format, opts)?;
    skin_io::atomic::write_bytes(path, e.text.as_bytes())?;
    Ok(())
}

const PRESETS: [(&str, Preset); 3] = [
    ("light", Preset::Light),
    ("medium", Preset::Medium),
    ("dark", Preset::Dark),
];

/// The knobs of the exports the engines read (a quick reference: the engines' own errors are
/// what is measured).
fn export_options() -> ExportOptions {
    ExportOptions {
        escapes: 1_000,
        volume_photons: 4_000,
        ..ExportOptions::default()
    }
}

fn materialx(opts: &EngineOptions, rows: &mut Vec<Row>) -> anyhow::Result<()> {
    for (name, preset) in PRESETS {
        let skin = SkinParams::preset(preset);
        let mut radii = Vec::new();
        for space in [ColourSpace::LinRec709, ColourSpace::AcesCg] {
            let path = opts.out.join(format!("{name}_openpbr_{space}.mtlx"));
            let eo = ExportOptions {
                colour_space: space,
                ..export_options()
            };
            write_export(&skin, Format::OpenPbr, &eo, &path)?;
            let v = driver(
                opts,
                "materialx_check.py",
                &[path.to_str().context("path")?],
            )?;
            if v["valid"] != serde_json::Value::Bool(true)
                || !v["unknown_inputs"].as_array().is_some_and(Vec::is_empty)
            {
                bail!("MaterialX rejects {}: {}", path.display(), v["message"]);
            }
            let text = std::fs::read_to_string(&path)?;
            let radius: f64 = text
                .lines()
                .find(|l| l.contains(r#"name="subsurface_radius""#))
                .and_then(|l| l.split("value=\"").nth(1))
                .and_then(|l| l.split('"').next())
                .context("no subsurface_radius")?
                .parse()?;
            let scale = numbers(&v["transformed"]["subsurface_radius_scale"]);
            radii.push((
                format!("MaterialX {}", v["version"].as_str().unwrap_or("?")),
                scale.iter().map(|s| s * radius).collect::<Vec<_>>(),
            ));
        }
        let (engine, aces) = radii.pop().context("two files")?;
        let (_, rec) = radii.pop().context("two files")?;
        for c in 0..3 {
            rows.push(Row {
                engine: engine.clone(),
                preset: name,
                quantity: "acescg mean free path through MaterialX colour management (mm)".into(),
                channel: ["R", "G", "B"][c].into(),
                ours: rec[c],
                engine_value: aces[c],
                engine_stderr: 0.0,
            });
        }
    }
    Ok(())
}

/// `skin spectrum`'s diffuse reflectance (per incident photon, exact) as a D65 colour in linear Rec.709.
fn diffuse_rgb(skin: &SkinParams) -> anyhow::Result<[f64; 3]> {
    let grid = WavelengthGrid::visible();
    let spectrum = skin_cli::spectrum::rows(skin, &grid, multipole::Method::Exact)?;
    Ok(reflectance_to_xyz(&GridSpectrum::new(
        grid,
        spectrum.iter().map(|r| r.diffuse_reflectance).collect(),
    )?)
    .to_linear_srgb()
    .0)
}

fn mitsuba(opts: &EngineOptions, rows: &mut Vec<Row>) -> anyhow::Result<()> {
    let llvm = std::env::var_os("DRJIT_LIBLLVM_PATH").is_some();
    let spp = opts.spp.to_string();
    for (name, preset) in PRESETS {
        let skin = SkinParams::preset(preset);
        let f0 = skin_export::Surface::of(&skin).f0();
        let rgb = diffuse_rgb(&skin)?;
        let mut cases = vec![(
            Variant::Rgb,
            if llvm { "llvm_ad_rgb" } else { "scalar_rgb" },
        )];
        if llvm {
            cases.push((Variant::Mono, "llvm_ad_mono"));
        }
        for (variant, mi_variant) in cases {
            let path = opts.out.join(format!("{name}_mitsuba_{variant}.xml"));
            let eo = ExportOptions {
                mitsuba_variant: variant,
                scene: true,
                ..export_options()
            };
            write_export(&skin, Format::Mitsuba, &eo, &path)?;
            let v = driver(
                opts,
                "mitsuba_render.py",
                &[path.to_str().context("path")?, mi_variant, &spp],
            )?;
            let engine = format!("Mitsuba {}", v["version"].as_str().unwrap_or("?"));
            let (mean, se) = (numbers(&v["mean"]), numbers(&v["stderr"]));
            let quantity = format!("slab under uniform sky, normal view ({mi_variant}, {spp} spp)");
            match variant {
                Variant::Mono => {
                    let ours = f0
                        + multipole::skin::diffuse_reflectance(
                            &skin,
                            skin_optics::Wavelength::new(eo.lambda_nm)?,
                            multipole::Method::Exact,
                        )?;
                    rows.push(Row {
                        engine,
                        preset: name,
                        quantity,
                        channel: format!("{} nm", eo.lambda_nm),
                        ours,
                        engine_value: mean[0],
                        engine_stderr: se[0],
                    });
                }
                _ => {
                    rows.extend(Row::rgb(
                        &engine,
                        name,
                        &quantity,
                        std::array::from_fn(|c| f0 + rgb[c]),
                        &mean,
                        std::array::from_fn(|c| se[c]),
                    ));
                }
            }
        }
    }
    Ok(())
}

fn mcx(opts: &EngineOptions, rows: &mut Vec<Row>) -> anyhow::Result<()> {
    let photons = opts.mcx_photons.to_string();
    for (name, preset) in PRESETS {
        let skin = SkinParams::preset(preset);
        let eo = ExportOptions {
            photons: opts.mcx_photons,
            ..export_options()
        };
        let path = opts.out.join(format!("{name}_mcx.json"));
        write_export(&skin, Format::Mcx, &eo, &path)?;
        let v = driver_with(
            opts,
            "mcx_run.py",
            &[path.to_str().context("path")?, &photons],
            opts.mcx_preload.as_deref(),
        )?;
        let ours = multipole::exact::adding_doubling::skin_total_reflectance(
            &skin,
            skin_optics::Wavelength::new(eo.lambda_nm)?,
            &multipole::exact::adding_doubling::AddingDoublingOptions::default(),
        )?;
        rows.push(Row {
            engine: format!("MCX ({})", v["version"].as_str().unwrap_or("?")),
            preset: name,
            quantity: format!(
                "reflectance per entering photon, {} photons, 20 mm dermis",
                opts.mcx_photons
            ),
            channel: format!("{} nm", eo.lambda_nm),
            ours,
            engine_value: v["reflectance"].as_f64().context("reflectance")?,
            engine_stderr: v["stderr"].as_f64().context("stderr")?,
        });
    }
    Ok(())
}

fn cycles(opts: &EngineOptions, rows: &mut Vec<Row>) -> anyhow::Result<()> {
    let spp = opts.cycles_spp.to_string();
    for (name, preset) in PRESETS {
        let skin = SkinParams::preset(preset);
        let f0 = skin_export::Surface::of(&skin).f0();
        let rgb = diffuse_rgb(&skin)?;
        let path = opts.out.join(format!("{name}_blender.py"));
        write_export(&skin, Format::Blender, &export_options(), &path)?;
        let file = path.to_str().context("path")?;
        let mut cases: Vec<(&str, &str)> = Vec::new();
        for method in skin_export::blender::CyclesMethod::ALL {
            cases.push(("slab", method.identifier()));
            cases.push(("sphere", method.identifier()));
        }
        cases.push(("volume", "-"));
        // Our layers' mean subsurface reflectance over what the sphere's mask sees, rendered
        // exactly by the volumetric slab at four view angles.
        let white = driver(opts, "cycles_render.py", &[file, "volume_white", "-", &spp])?;
        let (white_mean, white_se) = (numbers(&white["mean"]), numbers(&white["stderr"]));
        let mut ours_sphere: Option<([f64; 3], [f64; 3])> = None;
        for (scene, method) in cases {
            let v = driver(opts, "cycles_render.py", &[file, scene, method, &spp])?;
            let engine = format!("Cycles {}", v["version"].as_str().unwrap_or("?"));
            let (mean, se) = (numbers(&v["mean"]), numbers(&v["stderr"]));
            let (quantity, offset) = match scene {
                "volume" => (
                    format!(
                        "volume_slab() under uniform sky, normal view ({spp} spp): F(0) + diffuse"
                    ),
                    f0,
                ),
                "slab" => (
                    format!("Principled {method}, slab, normal view ({spp} spp): subsurface part"),
                    0.0,
                ),
                _ => (
                    format!(
                        "Principled {method}, sphere under white sky ({spp} spp): subsurface part"
                    ),
                    0.0,
                ),
            };
            rows.extend(Row::rgb(
                &engine,
                name,
                &quantity,
                std::array::from_fn(|c| offset + rgb[c]),
                &mean,
                std::array::from_fn(|c| se[c]),
            ));
            if scene == "sphere" {
                let view = sphere::SphereView {
                    radius_mm: v["radius_mm"].as_f64().context("sphere radius_mm")?,
                    mask: v["mask"].as_f64().context("sphere mask")?,
                    pixels: v["side"].as_u64().context("sphere side")? as usize,
                    spp: opts.sphere_spp,
                };
                let (walk_mean, walk_se) = match ours_sphere {
                    Some(x) => x,
                    None => *ours_sphere.insert(sphere::volumetric_sphere(name, view, None)?),
                };
                rows.extend(Row::rgb(
                    &engine,
                    name,
                    &format!(
                        "Principled {method}, sphere under white sky ({spp} spp): subsurface part against our volumetric walk on the same sphere ({} spp; its stderr added)",
                        opts.sphere_spp
                    ),
                    std::array::from_fn(|c| walk_mean[c]),
                    &mean,
                    std::array::from_fn(|c| se[c].hypot(walk_se[c])),
                ));
                rows.extend(Row::rgb(
                    &engine,
                    name,
                    &format!(
                        "Principled {method}, sphere under white sky ({spp} spp): subsurface part against our layers over the same view angles (volume_slab() at 4 angles; its stderr added)"
                    ),
                    std::array::from_fn(|c| white_mean[c]),
                    &mean,
                    std::array::from_fn(|c| se[c].hypot(white_se[c])),
                ));
            }
        }
    }
    Ok(())
}

/// Run every installed engine; write `engines.csv` and `engines.png` into `opts.out`. Returns the
/// rows and one note per engine skipped.
pub fn run_engines(opts: &EngineOptions) -> anyhow::Result<(Vec<Row>, Vec<String>)> {
    std::fs::create_dir_all(&opts.out).with_context(|| format!("--out {}", opts.out.display()))?;
    let mut rows = Vec::new();
    let mut notes = Vec::new();
    type Driver = fn(&EngineOptions, &mut Vec<Row>) -> anyhow::Result<()>;
    let engines: [(&str, &str, Driver); 4] = [
        ("MaterialX", "MaterialX", materialx),
        ("Mitsuba 3", "mitsuba", mitsuba),
        ("MCX (pmcxcl)", "pmcxcl", mcx),
        ("Blender Cycles", "bpy", cycles),
    ];
    for (label, module, run) in engines {
        if !opts.only.is_empty() && !opts.only.iter().any(|m| m == module) {
            continue;
        }
        if !importable(opts, module) {
            notes.push(format!(
                "{label}: skipped ({} cannot import {module})",
                opts.python.display()
            ));
            continue;
        }
        log::info!("{label}: running");
        run(opts, &mut rows)?;
    }
    notes.push(
        "Unreal, HDRP: cannot run here; their model-side error is what `skin export` prints".into(),
    );
    let mut csv = String::from(
        "engine,preset,quantity,channel,ours,engine_value,engine_stderr,rel_error,z\n",
    );
    for r in &rows {
        let z = if r.engine_stderr > 0.0 {
            format!("{:.2}", (r.engine_value - r.ours) / r.engine_stderr)
        } else {
            String::new()
        };
        let _ = writeln!(
            csv,
            "{},{},\"{}\",{},{:.6},{:.6},{:.6},{:.5},{z}",
            r.engine,
            r.preset,
            r.quantity,
            r.channel,
            r.ours,
            r.engine_value,
            r.engine_stderr,
            r.rel_error()
        );
    }
    skin_io::atomic::write_bytes(&opts.out.join("engines.csv"), csv.as_bytes())?;
    let mut chart = skin_plot::LineChart::new(
        "Engines against our exact numbers",
        "comparison (CSV row)",
        "engine / ours − 1 (%)",
    )
    .with_x_range(0.0, rows.len() as f64 + 1.0);
    let mut engines_seen: Vec<&str> = Vec::new();
    for r in &rows {
        if !engines_seen.contains(&r.engine.as_str()) {
            engines_seen.push(&r.engine);
        }
    }
    for (k, engine) in engines_seen.iter().enumerate() {
        let points = rows
            .iter()
            .enumerate()
            .filter(|(_, r)| r.engine == *engine)
            .map(|(i, r)| ((i + 1) as f64, 100.0 * r.rel_error()))
            .collect();
        chart = chart.with_series(
            skin_plot::Series::scatter(*engine, points).with_color(skin_plot::palette_color(k)),
        );
    }
    skin_plot::save_png(
        &opts.out.join("engines.png"),
        &[skin_plot::Panel::Line(chart)],
        900,
        500,
    )?;
    Ok((rows, notes))
}
