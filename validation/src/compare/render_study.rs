//! `skin-validate render`: the BSSRDF (`render::bssrdf`) against the volumetric reference
//! (`render::volumetric`, docs/physics.md §15) in image space.
//!
//! Every case is rendered twice with the same seed, camera and lights: by the BSSRDF at
//! `bssrdf_spp` and by the volumetric walk at `reference_spp`. The per-pixel relative error of the
//! luminance, (Y_bssrdf − Y_ref) / Y_ref, is drawn as a heat map (PNG) over the skin pixels lit above
//! 15% of the 95th percentile of a third, independent render (the BSSRDF at another seed: choosing
//! the pixels from either compared render's own values would keep the pixels where its noise happened
//! to be high, a bias of tens of percent for the heavy-tailed reference at low spp); the region's error ΣY_bssrdf / ΣY_ref − 1 and the mean
//! absolute per-pixel error (noise included, so large at low spp) go to
//! `render_cases.csv` with the noise of the mean signed error (standard error from both renders'
//! per-pixel variance passes), so a difference can be told from noise. A case *fails* when
//! |mean signed error| exceeds 5% and three standard errors. Every skin has `surface = "smooth"`:
//! then the BSSRDF's totals (adding-doubling under a Fresnel boundary) and the walk's boundary are
//! the same physics, and what differs is geometry (docs/physics.md §15).
//!
//! The error-against-time charts render the cases where a method fails (the 2-mm backlit slab,
//! the backlit ear, the 5-mm sphere under a sky; light skin) with the BSSRDF alone, the default
//! configuration (whatever `skin render` does with the scene, thin-part walks included) and the
//! volumetric walk at increasing spp, each image's RMS relative error and region error taken
//! against a separate volumetric run at 4× the largest count, CPU seconds of the process on the x
//! axis (`--charts` renders only these).
//!
//! `timed` builds its `RenderOptions` like `render`'s test helper `tests/common::run` does: a
//! library crate cannot use another crate's test scaffolding, and here the CPU time is measured
//! around the render.

use anyhow::Context;
use render::bssrdf::Curvature;
use render::film::Film;
use render::integrator::{BodyIntegrator, IntegratorKind};
use render::material::SkinKnobs;
use render::passes::Passes;
use render::renderer::{RenderOptions, render_with};
use render::scene::Scene;
use render::volumetric::shapes::box_obj;
use skin_plot::{HeatMap, LineChart, Panel, Series, SeriesStyle, save_png};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// How much each render of the study samples.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RenderStudy {
    /// Image side, pixels (analytic shapes; the ear and the head use 2× wide images).
    pub side: usize,
    /// Samples per pixel of the BSSRDF renders.
    pub bssrdf_spp: u32,
    /// Samples per pixel of the volumetric reference on the analytic shapes.
    pub reference_spp: u32,
    /// Samples per pixel of the volumetric reference on the ear and the head (their walks cost
    /// 3–10× more per sample).
    pub builtin_reference_spp: u32,
    /// spp ladder of the error-against-time chart.
    pub ladder: &'static [u32],
}

impl RenderStudy {
    /// Modest counts: a few CPU minutes.
    pub const QUICK: Self = Self {
        side: 24,
        bssrdf_spp: 16,
        reference_spp: 16,
        builtin_reference_spp: 16,
        ladder: &[1, 4],
    };
    /// The counts of BENCHMARKS.md, "BSSRDF against the volumetric reference".
    pub const FULL: Self = Self {
        side: 32,
        bssrdf_spp: 256,
        reference_spp: 64,
        builtin_reference_spp: 16,
        ladder: &[1, 4, 16, 32],
    };
}

/// Which cases one run of the study renders, and how, beyond the counts of [`RenderStudy`].
#[derive(Debug, Clone, Default)]
pub struct StudyRun {
    /// Only the cases whose label `name (tone)` contains one of these (every case when empty);
    /// the error-against-time chart is skipped when set.
    pub only: Vec<String>,
    /// Volumetric spp of the cases whose label contains the pattern (first match wins), in place
    /// of the study's counts: the ear, the head and the curved cases need more to reach a verdict.
    pub reference_spp_for: Vec<(String, u32)>,
    /// Folder where volumetric references are written and reused, keyed by the scene text, the
    /// image size, spp and seed (not by the code: empty it when the walk changes).
    pub reference_cache: Option<PathBuf>,
    /// Worker threads of every render (None = all cores).
    pub threads: Option<usize>,
    /// Only the error-against-time charts (of the chart cases `only` selects, every one when
    /// empty), no case table.
    pub charts_only: bool,
    /// The BSSRDF's curvature term (default on; `Curvature::Planar` for the former planar
    /// profile, docs/physics.md §8.2).
    pub curvature: Curvature,
}

impl StudyRun {
    fn wants(&self, label: &str) -> bool {
        self.only.is_empty() || self.only.iter().any(|p| label.contains(p.as_str()))
    }

    fn reference_spp(&self, label: &str) -> Option<u32> {
        self.reference_spp_for
            .iter()
            .find(|(p, _)| label.contains(p.as_str()))
            .map(|&(_, n)| n)
    }
}

/// One scene of the study and where its error is measured.
struct Case {
    name: String,
    tone: &'static str,
    toml: String,
    width: usize,
    height: usize,
    /// The built-in ear or head (sampled at `builtin_reference_spp`).
    builtin: bool,
    /// The region error above which (and above 3σ) the BSSRDF fails the case.
    tolerance: f64,
}

/// Region error above which (and above 3σ) the BSSRDF fails a case.
const TOLERANCE: f64 = 0.05;

/// The stricter verdict of the curved cases: the BSSRDF within 2% of the walk on a sphere.
const SPHERE_TOLERANCE: f64 = 0.02;

const TONES: [&str; 3] = ["light", "medium", "dark"];

/// Radii of the curved cases, mm: around and below the profiles' reach (r₉₉ 2–5 mm), where the
/// planar BSSRDF meets curvature (docs/physics.md §8.1).
const SPHERE_RADII_MM: [f32; 3] = [5.0, 10.0, 20.0];

/// How a sphere case is lit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum SphereLight {
    /// A uniform D65 sky of luminance 1.
    Sky,
    /// A sphere lamp 42° off the view axis (8.6° across) over a dim sky (0.02).
    Lamp,
}

impl SphereLight {
    const ALL: [Self; 2] = [Self::Sky, Self::Lamp];

    fn label(self) -> &'static str {
        match self {
            Self::Sky => "sky",
            Self::Lamp => "lamp",
        }
    }
}

/// A sphere of `radius_mm` filling 80% of the view, with the skin material `skin`, lit by `light`.
fn sphere_toml(skin: &str, radius_mm: f32, light: SphereLight) -> String {
    let lights = match light {
        SphereLight::Sky => "[environment]\nspectrum = \"d65\"\nintensity = 1\n".to_string(),
        SphereLight::Lamp => format!(
            "[environment]\nspectrum = \"d65\"\nintensity = 0.02\n\
             [[lights]]\ntype = \"sphere\"\ncenter_mm = [{x}, {y}, {z}]\nradius_mm = {lr}\nintensity = 12\n",
            x = 24.0 * radius_mm,
            y = 12.0 * radius_mm,
            z = 30.0 * radius_mm,
            lr = 3.0 * radius_mm,
        ),
    };
    format!(
        "[camera]\nposition_mm = [0, 0, {d}]\nlook_at_mm = [0, 0, 0]\nfov_deg = 11\n\
         {lights}{skin}[[meshes]]\nshape = \"sphere\"\nmaterial = \"skin\"\nunits_mm = {radius_mm}\n",
        d = 12.0 * radius_mm
    )
}

/// The analytic cases: a flat slab (central quarter of the view, away from the edges), spheres of
/// 5, 10 and 20 mm under a uniform sky and under a lamp, and 1-, 2- and 3-mm slabs lit from
/// behind; each skin tone.
fn analytic_cases(side: usize, dir: &Path) -> anyhow::Result<Vec<Case>> {
    let slab = dir.join("slab.obj");
    std::fs::write(&slab, box_obj([100.0, 100.0, 20.0]))?;
    let mut cases = Vec::new();
    for tone in TONES {
        let skin = format!(
            "[materials.skin]\ntype = \"skin\"\npreset = \"{tone}\"\nsurface = \"smooth\"\n"
        );
        // Flat slab seen from above: 20 mm of its top face fill the view.
        let slab_toml = format!(
            "[camera]\nposition_mm = [0, 0, 300]\nlook_at_mm = [0, 0, 0]\nfov_deg = 3.9\n\
             [environment]\nspectrum = \"d65\"\nintensity = 0.2\n{skin}\
             [[meshes]]\nfile = \"{}\"\nmaterial = \"skin\"\n\
             [[lights]]\ntype = \"sphere\"\ncenter_mm = [150, 0, 200]\nradius_mm = 60\nintensity = 3\n",
            slab.display()
        );
        cases.push(case("slab", tone, slab_toml, side));
        for r in SPHERE_RADII_MM {
            for light in SphereLight::ALL {
                let mut c = case(
                    &format!("sphere r={r} mm, {}", light.label()),
                    tone,
                    sphere_toml(&skin, r, light),
                    side,
                );
                c.tolerance = SPHERE_TOLERANCE;
                cases.push(c);
            }
        }
        for mm in [1.0f32, 2.0, 3.0] {
            let file = dir.join(format!("thin{mm}.obj"));
            std::fs::write(&file, box_obj([60.0, 60.0, mm]))?;
            // Lit from behind by a large quad; a weak sky from the front.
            let thin = format!(
                "[camera]\nposition_mm = [0, 0, 300]\nlook_at_mm = [0, 0, 0]\nfov_deg = 5.7\n\
                 [environment]\nspectrum = \"d65\"\nintensity = 0.02\n{skin}\
                 [[meshes]]\nfile = \"{}\"\nmaterial = \"skin\"\n\
                 [[lights]]\ntype = \"quad\"\ncenter_mm = [0, 0, -60]\nlook_at_mm = [0, 0, 0]\n\
                 size_mm = [200, 200]\nintensity = 5\n",
                file.display()
            );
            cases.push(case(
                &format!("thin slab {mm} mm (backlit)"),
                tone,
                thin,
                side,
            ));
        }
    }
    Ok(cases)
}

fn case(name: &str, tone: &'static str, toml: String, side: usize) -> Case {
    Case {
        name: name.to_string(),
        tone,
        toml,
        width: side,
        height: side,
        builtin: false,
        tolerance: TOLERANCE,
    }
}

/// The built-in backlit ear in each tone, and the default three-head scene (its three tones).
fn builtin_cases(side: usize) -> Vec<Case> {
    let mut cases: Vec<Case> = TONES
        .iter()
        .map(|tone| Case {
            name: "backlit ear".into(),
            tone,
            toml: untextured(render::builtin::EAR)
                .replace("preset = \"light\"", &format!("preset = \"{tone}\"")),
            width: 2 * side,
            height: 2 * side,
            builtin: true,
            tolerance: TOLERANCE,
        })
        .collect();
    cases.push(Case {
        name: "head, default lights".into(),
        tone: "all three",
        toml: untextured(render::builtin::THREE_HEADS_UNIFORM),
        width: 4 * side,
        height: 2 * side,
        builtin: true,
        tolerance: TOLERANCE,
    });
    cases
}

/// The scene without skin albedo textures (the volumetric walk has no texture modulation, so both
/// integrators see the same skin) and with the smooth surface on every skin.
fn untextured(toml: &str) -> String {
    toml.lines()
        .filter(|l| !l.trim_start().starts_with("albedo_texture"))
        .map(|l| {
            if l.trim() == "type = \"skin\"" {
                format!("{l}\nsurface = \"smooth\"")
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// A render of `scene` and the CPU seconds it took.
fn timed(
    case: &Loaded,
    w: usize,
    h: usize,
    spp: u32,
    seed: u64,
    threads: Option<usize>,
) -> anyhow::Result<(Film, f64)> {
    let opts = RenderOptions {
        width: w,
        height: h,
        spp,
        seed,
        threads,
        ..Default::default()
    };
    let settings = opts.validate()?;
    let t0 = cpu_time::ProcessTime::now();
    let (film, _) = render_with(&case.scene, &case.body, &settings, None)?;
    Ok((film, t0.elapsed().as_secs_f64()))
}

/// The volumetric reference of `case` at `spp`, from `cache` when it holds one of the same scene
/// text (`key_text`), size, spp and seed; rendered (and written there) otherwise. The CPU
/// seconds are those of the render that made it.
fn reference(
    case: &Case,
    key_text: &str,
    spp: u32,
    seed: u64,
    run: &StudyRun,
) -> anyhow::Result<(Film, f64)> {
    use std::hash::{Hash, Hasher};
    let mut hasher = std::collections::hash_map::DefaultHasher::new();
    key_text.hash(&mut hasher);
    let file = run.reference_cache.as_ref().map(|dir| {
        dir.join(format!(
            "{}-{}x{}-{spp}spp-seed{seed}-{:016x}.txt",
            stem(case),
            case.width,
            case.height,
            hasher.finish()
        ))
    });
    if let Some(f) = file.as_ref().filter(|f| f.exists()) {
        return read_cached(f, case.width, case.height, spp);
    }
    let vol = load(&case.toml, true, Curvature::default())?;
    let (film, t) = timed(&vol, case.width, case.height, spp, seed, run.threads)?;
    if let Some(f) = file {
        let mut text = format!("{t}\n");
        for i in 0..case.width * case.height {
            let (x, y) = (i % case.width, i / case.width);
            let [a, b, c] = film.xyz(x, y);
            let _ = writeln!(text, "{a:e} {b:e} {c:e} {:e}", film.variance(x, y));
        }
        if let Some(dir) = f.parent() {
            std::fs::create_dir_all(dir)?;
        }
        skin_io::atomic::write_bytes(&f, text.as_bytes())?;
    }
    Ok((film, t))
}

/// A reference written by [`reference`]: CPU seconds, then per pixel X Y Z and the variance of Y.
fn read_cached(f: &Path, w: usize, h: usize, spp: u32) -> anyhow::Result<(Film, f64)> {
    let text = std::fs::read_to_string(f).with_context(|| format!("reading {}", f.display()))?;
    let mut lines = text.lines();
    let t: f64 = lines.next().unwrap_or("").trim().parse()?;
    let (mut means, mut var) = (Vec::with_capacity(w * h), Vec::with_capacity(w * h));
    for line in lines {
        let v: Vec<f64> = line
            .split_whitespace()
            .map(str::parse)
            .collect::<Result<_, _>>()?;
        anyhow::ensure!(
            v.len() == 4,
            "{}: a line of {} values",
            f.display(),
            v.len()
        );
        means.push([v[0], v[1], v[2]]);
        var.push(v[3]);
    }
    anyhow::ensure!(
        means.len() == w * h,
        "{}: {} pixels, expected {}",
        f.display(),
        means.len(),
        w * h
    );
    Ok((Film::from_means(w, h, means, var, spp), t))
}

fn stem(c: &Case) -> String {
    format!("{}-{}", c.name, c.tone)
        .chars()
        .map(|ch| if ch.is_ascii_alphanumeric() { ch } else { '_' })
        .collect()
}

/// A loaded case: its scene and the state of the integrator of skin's body.
struct Loaded {
    scene: Scene,
    body: BodyIntegrator,
}

/// How skin's body is rendered in a run of the study.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Config {
    /// The BSSRDF at every hit (no volumetric walk at thin parts).
    BssrdfOnly,
    /// What `skin render` does with the scene as written (the default knobs).
    Default,
    /// The volumetric walk at every hit (the reference).
    Volumetric,
}

impl Config {
    const ALL: [Self; 3] = [Self::BssrdfOnly, Self::Default, Self::Volumetric];

    fn label(self) -> &'static str {
        match self {
            Self::BssrdfOnly => "BSSRDF",
            Self::Default => "default",
            Self::Volumetric => "volumetric",
        }
    }
}

fn load(toml: &str, volumetric: bool, curvature: Curvature) -> anyhow::Result<Loaded> {
    load_as(
        toml,
        if volumetric {
            Config::Volumetric
        } else {
            Config::Default
        },
        curvature,
    )
}

fn load_as(toml: &str, config: Config, curvature: Curvature) -> anyhow::Result<Loaded> {
    let mut knobs = SkinKnobs {
        curvature,
        ..SkinKnobs::default()
    };
    if config == Config::BssrdfOnly {
        // A thin-walk length of 0 never walks (the BSSRDF at every hit), whatever the default.
        knobs.fidelity.thin_walk_r99 = Some(0.0);
    }
    let scene = Scene::from_toml(toml, "study.toml", None, &knobs)?;
    let kind = if config == Config::Volumetric {
        IntegratorKind::Volumetric
    } else {
        IntegratorKind::Bssrdf
    };
    let body = BodyIntegrator::build(&scene, kind);
    Ok(Loaded { scene, body })
}

/// Pixels compared: skin at the first hit, lit above 15% of the 95th percentile of `pilot`, a
/// render independent of both compared ones (so the choice does not follow their noise).
fn compared_pixels(pilot: &Film, skin: &[f32]) -> Vec<usize> {
    let (w, h) = pilot.size();
    let y: Vec<f64> = (0..w * h)
        .map(|i| f64::from(pilot.xyz(i % w, i / w)[1]))
        .collect();
    let mut sorted: Vec<f64> = y
        .iter()
        .zip(skin)
        .filter(|&(_, &s)| s > 0.5)
        .map(|(v, _)| *v)
        .collect();
    sorted.sort_by(f64::total_cmp);
    let Some(&p95) = sorted.get(sorted.len() * 95 / 100) else {
        return Vec::new();
    };
    (0..w * h)
        .filter(|&i| skin[i] > 0.5 && y[i] > 0.15 * p95 && y[i] > 0.0)
        .collect()
}

/// Per-pixel relative luminance error of `test` against `reference` (NaN outside `pixels`).
fn error_map(test: &Film, reference: &Film, pixels: &[usize]) -> Vec<f64> {
    let (w, h) = reference.size();
    let mut map = vec![f64::NAN; w * h];
    for &i in pixels {
        let (x, y) = (i % w, i / w);
        let r = f64::from(reference.xyz(x, y)[1]);
        map[i] = (f64::from(test.xyz(x, y)[1]) - r) / r;
    }
    map
}

/// One row of the case table.
struct CaseResult {
    mean_signed: f64,
    mean_abs: f64,
    /// Standard error of `mean_signed` from both renders' noise.
    noise: f64,
    pixels: usize,
}

fn measure(test: &Film, reference: &Film, pixels: &[usize], map: &[f64]) -> CaseResult {
    let (w, _) = reference.size();
    // Ratio of the region's sums, not the mean of per-pixel ratios: a noisy denominator biases
    // the latter upwards by about the reference's relative variance per pixel (Jensen).
    let y = |f: &Film, i: usize| f64::from(f.xyz(i % w, i / w)[1]);
    let (sum_t, sum_r) = pixels.iter().fold((0.0, 0.0), |(a, b), &i| {
        (a + y(test, i), b + y(reference, i))
    });
    let mean_signed = if sum_r > 0.0 {
        sum_t / sum_r - 1.0
    } else {
        f64::NAN
    };
    // A reference pixel of zero (no path found light) has no relative error: left out.
    let finite: Vec<f64> = pixels
        .iter()
        .map(|&i| map[i].abs())
        .filter(|e| e.is_finite())
        .collect();
    let mean_abs = finite.iter().sum::<f64>() / finite.len().max(1) as f64;
    // Standard error of that ratio from both renders' noise (first order):
    // √(Σ var_test,i + Σ var_ref,i) / Σ Y_ref,i.
    let var: f64 = pixels
        .iter()
        .map(|&i| reference.variance(i % w, i / w) + test.variance(i % w, i / w))
        .sum();
    CaseResult {
        mean_signed,
        mean_abs,
        noise: var.sqrt() / sum_r.max(1e-30),
        pixels: pixels.len(),
    }
}

fn heat(title: &str, film: &Film, map: Vec<f64>) -> Panel {
    let (w, h) = film.size();
    // Rows from the top of the image down, y axis upwards: flip so the map is upright.
    let mut values = Vec::with_capacity(w * h);
    for y in (0..h).rev() {
        values.extend_from_slice(&map[y * w..(y + 1) * w]);
    }
    Panel::Heat(HeatMap {
        title: title.to_string(),
        x_label: "pixel x".into(),
        y_label: "pixel y (up)".into(),
        value_label: "(BSSRDF − volumetric) / volumetric".into(),
        x_range: (0.0, w as f64),
        y_range: (0.0, h as f64),
        log_x: false,
        log_y: false,
        nx: w,
        ny: h,
        values,
        value_range: Some((-0.5, 0.5)),
        overlay: Vec::new(),
    })
}

/// Run the study into `out`: error maps, `render_cases.csv`, per chart case
/// `render_time_<case>.csv` and `.png`, and `render.md` (the table and the charts' lines).
pub fn run_render(study: RenderStudy, run: &StudyRun, out: &Path) -> anyhow::Result<String> {
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let meshes = tempfile::tempdir()?;
    let mesh_dir = meshes.path().display().to_string();
    let mut cases = analytic_cases(study.side, meshes.path())?;
    cases.extend(builtin_cases(study.side));
    let mut csv = String::from(
        "case,tone,pixels,mean_signed_error,mean_abs_error,noise,fails,bssrdf_cpu_s,volumetric_cpu_s,volumetric_spp\n",
    );
    let mut table = String::from(
        "| case | tone | volumetric spp | pixels | mean error | mean abs error | noise (1σ) | BSSRDF fails? | CPU s (BSSRDF / volumetric) |\n|---|---|---|---|---|---|---|---|---|\n",
    );
    let mut chart = String::new();
    let skip_chart = !run.only.is_empty() && !run.charts_only;
    for (k, c) in cases.iter().enumerate() {
        let label = format!("{} ({})", c.name, c.tone);
        if run.charts_only || !run.wants(&label) {
            continue;
        }
        log::info!("[{}/{}] {label}", k + 1, cases.len());
        let bssrdf = load(&c.toml, false, run.curvature)?;
        let (test, t_b) = timed(&bssrdf, c.width, c.height, study.bssrdf_spp, 1, run.threads)?;
        let ref_spp = run.reference_spp(&label).unwrap_or(if c.builtin {
            study.builtin_reference_spp
        } else {
            study.reference_spp
        });
        let key_text = c.toml.replace(&mesh_dir, "<meshes>");
        let (reference, t_v) = reference(c, &key_text, ref_spp, 2, run)?;
        let (pilot, _) = timed(&bssrdf, c.width, c.height, study.bssrdf_spp, 3, run.threads)?;
        let skin = Passes::first_hit(&bssrdf.scene, c.width, c.height).skin;
        let pixels = compared_pixels(&pilot, &skin);
        let map = error_map(&test, &reference, &pixels);
        let r = measure(&test, &reference, &pixels, &map);
        let fails = r.mean_signed.abs() > c.tolerance && r.mean_signed.abs() > 3.0 * r.noise;
        let stem = stem(c);
        let title = format!("{} ({}): BSSRDF vs volumetric", c.name, c.tone);
        save_png(
            &out.join(format!("error_{stem}.png")),
            &[heat(&title, &reference, map)],
            900,
            700,
        )?;
        let _ = writeln!(
            csv,
            "\"{}\",{},{},{:.5},{:.5},{:.5},{},{:.2},{:.2},{ref_spp}",
            c.name, c.tone, r.pixels, r.mean_signed, r.mean_abs, r.noise, fails, t_b, t_v
        );
        let _ = writeln!(
            table,
            "| {} | {} | {ref_spp} | {} | {:+.1}% | {:.1}% | {:.1}% | {} | {:.1} / {:.1} |",
            c.name,
            c.tone,
            r.pixels,
            100.0 * r.mean_signed,
            100.0 * r.mean_abs,
            100.0 * r.noise,
            if fails { "**yes**" } else { "no" },
            t_b,
            t_v
        );
        // Written after every case, so a long run that is stopped keeps what it measured.
        skin_io::atomic::write_bytes(&out.join("render_cases.csv"), csv.as_bytes())?;
        write_md(study, out, &table, &chart)?;
    }
    if !skip_chart {
        for label in CHART_CASES {
            let Some(c) = cases
                .iter()
                .find(|c| format!("{} ({})", c.name, c.tone) == label)
            else {
                anyhow::bail!("no case {label}");
            };
            if !run.wants(label) {
                continue;
            }
            log::info!("error against time: {label}");
            chart.push_str(&time_chart(study, c, run, out)?);
            write_md(study, out, &table, &chart)?;
        }
    }
    write_md(study, out, &table, &chart)
}

/// The cases of the error-against-time charts: where a method fails (a thin backlit slab, the
/// backlit ear, a small sphere).
const CHART_CASES: [&str; 3] = [
    "thin slab 2 mm (backlit) (light)",
    "backlit ear (light)",
    "sphere r=5 mm, sky (light)",
];

/// Write `render.md` (the case table so far and the chart's lines); returns its text.
fn write_md(study: RenderStudy, out: &Path, table: &str, chart: &str) -> anyhow::Result<String> {
    let md = format!(
        "# BSSRDF against the volumetric reference\n\nspp: BSSRDF {}, volumetric {} (ear and head {}) unless the table says otherwise; image side {} px.\n\n{table}\n{chart}\n",
        study.bssrdf_spp, study.reference_spp, study.builtin_reference_spp, study.side
    );
    skin_io::atomic::write_bytes(&out.join("render.md"), md.as_bytes())?;
    Ok(md)
}

/// RMS relative luminance error of `test` against `reference` over `pixels`.
fn rms_error(test: &Film, reference: &Film, pixels: &[usize]) -> f64 {
    let map = error_map(test, reference, pixels);
    let n = pixels.len().max(1) as f64;
    (pixels.iter().map(|&i| map[i] * map[i]).sum::<f64>() / n).sqrt()
}

/// Error against CPU time on `case` for each [`Config`]: every image's region error (plotted, as
/// its magnitude) and RMS relative per-pixel error against a volumetric run at 4× the ladder's top
/// spp (another seed), CPU seconds of the process on the x axis; `render_time_<case>.csv` and
/// `.png`. Returns the markdown lines.
fn time_chart(
    study: RenderStudy,
    case: &Case,
    run: &StudyRun,
    out: &Path,
) -> anyhow::Result<String> {
    let top = *study.ladder.last().unwrap_or(&16);
    let threads = run.threads;
    let (w, h) = (case.width, case.height);
    let vol = load_as(&case.toml, Config::Volumetric, run.curvature)?;
    let (reference, t_ref) = timed(&vol, w, h, 4 * top, 99, threads)?;
    let default = load_as(&case.toml, Config::Default, run.curvature)?;
    let (pilot, _) = timed(&default, w, h, study.bssrdf_spp, 3, threads)?;
    let skin = Passes::first_hit(&default.scene, w, h).skin;
    let pixels = compared_pixels(&pilot, &skin);
    let stem = stem(case);
    let mut csv = String::from(
        "configuration,spp,cpu_s,rms_relative_error,region_error,region_noise,paths_per_cpu_s\n",
    );
    let mut lines = format!(
        "Error against time, {} ({}) (reference: volumetric at {} spp, {:.1} CPU s; `render_time_{stem}.png`):\n\n\
         | configuration | spp | CPU s | RMS rel. error | region error | noise (1σ) | camera paths per CPU-s |\n|---|---|---|---|---|---|---|\n",
        case.name,
        case.tone,
        4 * top,
        t_ref
    );
    let mut series = Vec::new();
    for config in Config::ALL {
        let loaded = if config == Config::Volumetric {
            &vol
        } else if config == Config::Default {
            &default
        } else {
            &load_as(&case.toml, config, run.curvature)?
        };
        let mut pts = Vec::new();
        for &spp in study.ladder {
            let (film, t) = timed(loaded, w, h, spp, 7, threads)?;
            let e = rms_error(&film, &reference, &pixels);
            let map = error_map(&film, &reference, &pixels);
            let r = measure(&film, &reference, &pixels, &map);
            let paths = (w * h) as f64 * f64::from(spp) / t.max(1e-9);
            let name = config.label();
            let _ = writeln!(
                csv,
                "{name},{spp},{t:.3},{e:.5},{:.5},{:.5},{paths:.0}",
                r.mean_signed, r.noise
            );
            let _ = writeln!(
                lines,
                "| {name} | {spp} | {t:.2} | {:.1}% | {:+.1}% | {:.1}% | {paths:.0} |",
                100.0 * e,
                100.0 * r.mean_signed,
                100.0 * r.noise
            );
            // The region's error (bias and noise together) falls to the reference's noise for an
            // unbiased method and levels off at the bias for one that is not.
            pts.push((t, r.mean_signed.abs().max(1e-4)));
        }
        series.push(Series::line(config.label(), pts).with_style(SeriesStyle::LinePoints));
    }
    lines.push('\n');
    skin_io::atomic::write_bytes(&out.join(format!("render_time_{stem}.csv")), csv.as_bytes())?;
    let title = format!("{} ({}): error against render time", case.name, case.tone);
    let mut chart = LineChart::new(
        title,
        "CPU seconds",
        "|region luminance error| against the volumetric reference",
    )
    .log_x()
    .log_y();
    for s in series {
        chart = chart.with_series(s);
    }
    save_png(
        &out.join(format!("render_time_{stem}.png")),
        &[Panel::Line(chart)],
        900,
        600,
    )?;
    Ok(lines)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A grey film of luminance `y` per pixel, each with variance `var` of its mean.
    fn film(y: &[f64], var: f64) -> Film {
        let n = y.len();
        Film::from_means(
            n,
            1,
            y.iter().map(|&v| [v, v, v]).collect(),
            vec![var; n],
            16,
        )
    }

    /// The region's error of a noise-free test against a heavy-tailed reference of the same
    /// expectation (each pixel 0, or 20 with probability 1/20, as a walk that rarely finds the
    /// light: mean 1) is zero within its noise. Choosing the pixels from the reference's own
    /// values kept only the lucky pixels and gave −95%; with an independent pilot the error of
    /// 4,000 pixels is within 4σ (σ from the variance pass, here the exact variance 19 per pixel).
    #[test]
    fn region_error_is_unbiased_under_a_heavy_tailed_reference() {
        use rand::{Rng, SeedableRng};
        let n = 4000;
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(5);
        let reference: Vec<f64> = (0..n)
            .map(|_| {
                if rng.random::<f64>() < 0.05 {
                    20.0
                } else {
                    0.0
                }
            })
            .collect();
        let reference = film(&reference, 19.0);
        let test = film(&vec![1.0; n], 0.0);
        let pilot = film(&vec![1.0; n], 0.0);
        let skin = vec![1.0f32; n];
        let pixels = compared_pixels(&pilot, &skin);
        assert_eq!(pixels.len(), n, "every lit skin pixel is compared");
        let map = error_map(&test, &reference, &pixels);
        let r = measure(&test, &reference, &pixels, &map);
        assert!(
            r.mean_signed.abs() <= 4.0 * r.noise,
            "{} ± {}",
            r.mean_signed,
            r.noise
        );
        // The old choice, from the reference itself, is what this test guards against.
        let biased = compared_pixels(&reference, &skin);
        let map = error_map(&test, &reference, &biased);
        let b = measure(&test, &reference, &biased, &map);
        assert!(b.mean_signed < -0.9, "{}", b.mean_signed);
    }
}
