//! Our volumetric reference (`render::volumetric`) beside Mitsuba 3's volumetric path tracer
//! (`volpath`) on one matched scene (BENCHMARKS.md, "Volumetric reference"): a sphere of radius
//! 10 mm (`TriangleMesh::sphere(4)`, the same OBJ for both) with a smooth dielectric surface of
//! index 1.4 under a constant sky of radiance 1, seen from 60 mm through a 24° field of view at
//! 550 nm; box pixel filter, no depth limit in Mitsuba. Two bodies (`SCENE`):
//!
//! - `skin` (default): two-layer skin C_m 0.05, β_m 0.7, C_h 0.02 with an isotropic phase
//!   (`phase_g = 0`), its layers from `multipole::LayeredMedium::skin` at 550 nm; Mitsuba's
//!   dermis is an index-matched (`null`) inner sphere, the same mesh scaled to R − d_epi, whose
//!   faces lie d_epi · 0.998 under the outer ones (our epidermis: within d_epi of the mesh);
//! - `homogeneous`: σa 0.3 mm⁻¹, σs 60 mm⁻¹ (light skin's dermis at 550 nm, σs' 6 mm⁻¹),
//!   Henyey–Greenstein g 0.9.
//!
//! For each round the two renderers alternate, each rendering the image twice (two seeds) on one
//! thread. Over the pixels whose centre lies within 0.9 of the sphere's projected radius it
//! reports (a) the mean radiance of both, with its standard error from the two seeds' difference,
//! so the integrators can be checked against each other, and (b) camera paths per CPU-second and
//! the per-path variance σ₁² = spp · ⟨(a − b)²⟩ / 2; the equal-noise speed ratio is
//! (paths/s ÷ σ₁²)_ours / (paths/s ÷ σ₁²)_Mitsuba.
//!
//! Mitsuba runs in a Python outside this tree (`validation/examples/mitsuba_sphere.py`):
//! `cargo run --release -p validation --features studies --example mitsuba_side_by_side -- PYTHON [VARIANT]
//! [RR_DEPTH] [ROUNDS] [SPP] [SIDE] [SCENE]` (defaults llvm_ad_mono, Mitsuba's own rr_depth 5, 3
//! rounds, 32 spp, 48 px, skin), PYTHON a python with `mitsuba` and `numpy` installed (the LLVM
//! variants need libLLVM ≥ 16, e.g. `DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM-19.so`).
//! CPU time: ours from the process clock around `render` (a rayon pool of one thread), Mitsuba's
//! from `time.process_time()` around `mi.render` after a warm-up render (the LLVM kernels compiled
//! once, not counted).

use anyhow::Context;
use multipole::LayeredMedium;
use render::integrator::{BodyIntegrator, IntegratorKind};
use render::material::Material;
use render::material::SkinKnobs;
use render::renderer::{RenderOptions, render_with};
use render::scene::Scene;
use render::volumetric::guide::DEFAULT_GUIDED_FRACTION;
use render::volumetric::shapes::sphere_obj;
use render::volumetric::walk::ROULETTE_BELOW;
use render::volumetric::{LayerTables, SkinVolume, Volumetric};
use skin_optics::Wavelength;
use std::path::Path;
use std::process::Command;

const RADIUS_MM: f32 = 10.0;
const DISTANCE_MM: f32 = 60.0;
const FOV_DEG: f32 = 24.0;
const SIGMA_A: f32 = 0.3;
const SIGMA_S: f32 = 60.0;
const G: f64 = 0.9;
const ETA: f32 = 1.4;
const NM: f32 = 550.0;
/// The two-layer skin's melanin C_m, eumelanin blend β_m and hemoglobin C_h.
const SKIN: [f64; 3] = [0.05, 0.7, 0.02];

/// The matched body.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Body {
    /// Two-layer skin ([`SKIN`]), isotropic phase.
    Skin,
    /// σa [`SIGMA_A`], σs [`SIGMA_S`], g [`G`].
    Homogeneous,
}

/// What Mitsuba is given: (σa, σs) of the outer medium (mm⁻¹), and for two layers the dermis'
/// with d_epi (mm); g and η.
#[derive(Debug, Clone, Copy)]
struct Media {
    outer: (f64, f64),
    dermis: Option<((f64, f64), f64)>,
    g: f64,
    eta: f64,
}

/// Our walk's knobs: the guided fraction and the roulette weight.
#[derive(Debug, Clone, Copy)]
struct Knobs {
    guided: f64,
    roulette: f64,
}

impl Knobs {
    fn apply(self, v: SkinVolume) -> anyhow::Result<SkinVolume> {
        Ok(v.with_guided_fraction(self.guided)?
            .with_roulette_below(self.roulette)?)
    }
}

/// Our scene: the OBJ under the constant sky with the body, and what Mitsuba is to be given.
fn our_scene(
    dir: &Path,
    body: Body,
    knobs: Knobs,
) -> anyhow::Result<((Scene, BodyIntegrator), Media)> {
    let keys = match body {
        Body::Skin => format!(
            "melanin = {}\neumelanin = {}\nhemoglobin = {}\nphase_g = 0",
            SKIN[0], SKIN[1], SKIN[2]
        ),
        Body::Homogeneous => format!("phase_g = {G}"),
    };
    let text = format!(
        "[camera]\nposition_mm = [0, 0, {DISTANCE_MM}]\nlook_at_mm = [0, 0, 0]\nfov_deg = {FOV_DEG}\n\
         [environment]\nspectral_radiance = 1\n\
         [materials.skin]\ntype = \"skin\"\nsurface = \"smooth\"\n{keys}\n\
         [[meshes]]\nfile = \"sphere.obj\"\nmaterial = \"skin\"\n"
    );
    let scene = Scene::from_toml(&text, "sphere.toml", Some(dir), &SkinKnobs::default())?;
    if body == Body::Skin {
        let Material::Skin(skin) = &scene.materials[0] else {
            anyhow::bail!("the sphere is not skin");
        };
        let medium = LayeredMedium::skin(&skin.params, Wavelength::new(f64::from(NM))?, 0.0)?;
        let layers = medium.layers();
        let (e, d) = (layers[0], layers[layers.len() - 1]);
        let media = Media {
            outer: (e.sigma_a(), e.sigma_s()),
            dermis: Some((
                (d.sigma_a(), d.sigma_s()),
                skin.params.epidermis_thickness_mm(),
            )),
            g: 0.0,
            eta: skin.params.eta(),
        };
        let BodyIntegrator::Volumetric(mut walked) =
            BodyIntegrator::build(&scene, IntegratorKind::Volumetric)
        else {
            anyhow::bail!("not the volumetric integrator");
        };
        for m in &mut walked.media {
            if let Some(v) = m.take() {
                *m = Some(knobs.apply(v)?);
            }
        }
        return Ok(((scene, BodyIntegrator::Volumetric(walked)), media));
    }
    let volume = knobs.apply(SkinVolume::new(
        LayerTables::constant(SIGMA_A, SIGMA_S),
        LayerTables::constant(SIGMA_A, SIGMA_S),
        G,
        ETA,
        0.1,
        scene.geometry.triangles_of(0),
    ))?;
    let integrator = BodyIntegrator::Volumetric(Volumetric {
        media: vec![Some(volume)],
    });
    let media = Media {
        outer: (f64::from(SIGMA_A), f64::from(SIGMA_S)),
        dermis: None,
        g: G,
        eta: f64::from(ETA),
    };
    Ok(((scene, integrator), media))
}

/// Pixels whose centre lies within 0.9 of the sphere's projected radius (row-major).
fn region(side: usize) -> Vec<usize> {
    let half = (0.5 * FOV_DEG).to_radians().tan();
    let r_px = (RADIUS_MM / DISTANCE_MM).asin().tan() / half * 0.5 * side as f32;
    let c = 0.5 * side as f32;
    (0..side * side)
        .filter(|&i| {
            let (x, y) = ((i % side) as f32 + 0.5 - c, (i / side) as f32 + 0.5 - c);
            x.hypot(y) <= 0.9 * r_px
        })
        .collect()
}

/// Region mean of both images, its standard error, and the per-path variance σ₁².
fn stats(a: &[f64], b: &[f64], pixels: &[usize], spp: u32) -> (f64, f64, f64) {
    let n = pixels.len() as f64;
    let mean = pixels.iter().map(|&i| 0.5 * (a[i] + b[i])).sum::<f64>() / n;
    let d2 = pixels.iter().map(|&i| (a[i] - b[i]).powi(2)).sum::<f64>() / n;
    // var(one image's pixel) ≈ (a − b)² / 2; the pair's mean halves it; n pixels.
    let se = (d2 / 4.0 / n).sqrt();
    (mean, se, f64::from(spp) * d2 / 2.0)
}

/// One of our renders: the grey image and its CPU seconds.
fn ours(
    (scene, body): &(Scene, BodyIntegrator),
    side: usize,
    spp: u32,
    seed: u64,
) -> anyhow::Result<(Vec<f64>, f64)> {
    let opts = RenderOptions {
        width: side,
        height: side,
        spp,
        seed,
        threads: Some(1),
        wavelength_nm: Some(NM),
        ..Default::default()
    };
    let settings = opts.validate()?;
    let t0 = cpu_time::ProcessTime::now();
    let (film, _) = render_with(scene, body, &settings, None)?;
    let cpu = t0.elapsed().as_secs_f64();
    let img = (0..side * side)
        .map(|i| f64::from(film.linear_srgb(i % side, i / side)[1]))
        .collect();
    Ok((img, cpu))
}

/// Mitsuba's two renders (seeds `seeds`): images and CPU seconds each.
#[allow(clippy::too_many_arguments)] // the renderer, its scene and its film
fn mitsuba(
    python: &str,
    variant: &str,
    rr_depth: u32,
    media: &Media,
    dir: &Path,
    side: usize,
    spp: u32,
    seeds: [u64; 2],
) -> anyhow::Result<Vec<(Vec<f64>, f64)>> {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/mitsuba_sphere.py");
    let prefix = dir.join("mitsuba");
    let out = Command::new(python)
        .arg(&script)
        .args([variant, "1", &rr_depth.to_string()])
        .arg(dir.join("sphere.obj"))
        .args([
            side.to_string(),
            spp.to_string(),
            DISTANCE_MM.to_string(),
            FOV_DEG.to_string(),
            media.outer.0.to_string(),
            media.outer.1.to_string(),
            media.g.to_string(),
            media.eta.to_string(),
        ])
        .arg(&prefix)
        .args(media.dermis.iter().flat_map(|((sa, ss), _)| {
            [
                "--dermis".to_string(),
                dir.join("dermis.obj").display().to_string(),
                sa.to_string(),
                ss.to_string(),
            ]
        }))
        .args(seeds.map(|s| s.to_string()))
        .output()
        .with_context(|| format!("running {python}"))?;
    anyhow::ensure!(
        out.status.success(),
        "{python} {}: {}",
        script.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    let mut runs = Vec::new();
    for (seed, line) in seeds.iter().zip(
        text.lines()
            .filter_map(|l| l.find("seed ").map(|k| &l[k..])),
    ) {
        let cpu: f64 = line
            .rsplit(' ')
            .next()
            .context("cpu_s")?
            .parse()
            .with_context(|| format!("Mitsuba's line {line:?}"))?;
        let bytes = std::fs::read(format!("{}-{seed}.f32", prefix.display()))?;
        let img: Vec<f64> = bytes
            .chunks_exact(4)
            .map(|c| f64::from(f32::from_le_bytes([c[0], c[1], c[2], c[3]])))
            .collect();
        anyhow::ensure!(
            img.len() == side * side,
            "Mitsuba's image has {} values",
            img.len()
        );
        runs.push((img, cpu));
    }
    anyhow::ensure!(runs.len() == 2, "Mitsuba printed {text:?}");
    Ok(runs)
}

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let python = args.get(1).context(
        "usage: mitsuba_side_by_side PYTHON|none [VARIANT] [RR_DEPTH] [ROUNDS] [SPP] [SIDE] [SCENE] \
         [GUIDED] [ROULETTE]",
    )?;
    let variant = args.get(2).map_or("llvm_ad_mono", String::as_str);
    let num = |k: usize, d: u32| args.get(k).map_or(Ok(d), |s| s.parse::<u32>());
    let (rr_depth, rounds) = (num(3, 5)?, num(4, 3)?);
    let (spp, side) = (num(5, 32)?, num(6, 48)? as usize);
    let body = match args.get(7).map_or("skin", String::as_str) {
        "skin" => Body::Skin,
        "homogeneous" => Body::Homogeneous,
        other => anyhow::bail!("SCENE {other:?}: skin or homogeneous"),
    };
    let real = |k: usize, d: f64| args.get(k).map_or(Ok(d), |s| s.parse::<f64>());
    let knobs = Knobs {
        guided: real(8, DEFAULT_GUIDED_FRACTION)?,
        roulette: real(9, ROULETTE_BELOW)?,
    };
    let dir = tempfile::tempdir()?;
    std::fs::write(dir.path().join("sphere.obj"), sphere_obj(4, RADIUS_MM))?;
    let (scene, media) = our_scene(dir.path(), body, knobs)?;
    if let Some((_, d_epi)) = media.dermis {
        std::fs::write(
            dir.path().join("dermis.obj"),
            sphere_obj(4, RADIUS_MM - d_epi as f32),
        )?;
    }
    println!("{body:?} sphere; our walk {knobs:?}; Mitsuba's media {media:?}");
    let pixels = region(side);
    let paths = (side * side) as f64 * f64::from(spp);
    println!(
        "{side}×{side} px, {spp} spp, {} region pixels, Mitsuba {variant} (rr_depth {rr_depth}); one thread each",
        pixels.len()
    );
    println!(
        "round | ours: mean ± se, paths/CPU-s, σ₁ | Mitsuba: mean ± se, paths/CPU-s, σ₁ | equal-noise ratio"
    );
    let mut sums = [(0.0, 0.0, 0.0, 0.0); 2];
    for round in 0..u64::from(rounds) {
        let seeds = [2 * round + 1, 2 * round + 2];
        let (a, ta) = ours(&scene, side, spp, seeds[0])?;
        let (b, tb) = ours(&scene, side, spp, seeds[1])?;
        if python == "none" {
            let (mean, se, var1) = stats(&a, &b, &pixels, spp);
            let rate = 2.0 * paths / (ta + tb);
            println!(
                "{round} | {mean:.5} ± {se:.5}, {rate:.0}, {:.3} | efficiency {:.0}",
                var1.sqrt(),
                rate / var1
            );
            continue;
        }
        let m = mitsuba(
            python,
            variant,
            rr_depth,
            &media,
            dir.path(),
            side,
            spp,
            seeds,
        )?;
        let mut row = Vec::new();
        for (k, (x, y, t)) in [
            (a, b, ta + tb),
            (m[0].0.clone(), m[1].0.clone(), m[0].1 + m[1].1),
        ]
        .into_iter()
        .enumerate()
        {
            let (mean, se, var1) = stats(&x, &y, &pixels, spp);
            let rate = 2.0 * paths / t;
            let s = &mut sums[k];
            *s = (s.0 + mean, s.1 + se * se, s.2 + 2.0 * paths, s.3 + t);
            row.push((mean, se, rate, var1));
        }
        let ratio = (row[0].2 / row[0].3) / (row[1].2 / row[1].3);
        println!(
            "{round} | {:.5} ± {:.5}, {:.0}, {:.3} | {:.5} ± {:.5}, {:.0}, {:.3} | {ratio:.2}",
            row[0].0,
            row[0].1,
            row[0].2,
            row[0].3.sqrt(),
            row[1].0,
            row[1].1,
            row[1].2,
            row[1].3.sqrt()
        );
    }
    if python == "none" {
        return Ok(());
    }
    let r = f64::from(rounds);
    let [o, mi] = sums.map(|(m, se2, p, t)| (m / r, se2.sqrt() / r, p / t));
    println!(
        "all rounds: ours {:.5} ± {:.5} ({:.0} paths/CPU-s), Mitsuba {:.5} ± {:.5} ({:.0} paths/CPU-s); difference {:+.2}% ({:.1}σ)",
        o.0,
        o.1,
        o.2,
        mi.0,
        mi.1,
        mi.2,
        100.0 * (o.0 / mi.0 - 1.0),
        (o.0 - mi.0) / o.1.hypot(mi.1)
    );
    Ok(())
}
