//! The built-in head's lips before and after the renderer reads the thin epidermis of their texels
//! (docs/physics.md §19): one head with its maps fitted at load (`fit_maps = "auto-rgb"`, as
//! `builtin:three-heads`), under a uniform D65 sky of luminance 1 (a white diffuser renders as
//! linear sRGB (1, 1, 1)), seen close up along the lips' mean normal. Renders with
//! `thin_epidermis = false` (every texel under the material's 0.25 mm epidermis: the renderer
//! before) and with the flag read (0.05 mm under the lips), with the default integrator. The lip
//! texels are the thin ones as red as the vermilion (a* > 27, 40 < L* < 56 as given), the lip
//! pixels those whose primary ray hits one; their mean colour is compared in CIELAB (ΔE2000) with
//! the mean of the lip texels at the fit's exposure (linear texel ×
//! gains: the colour the fitted skin reproduces), raw and with the render's luminance scaled to
//! the texture's (shading and the sky's occlusion darken a render, not the texture). Writes
//! OUT/lips_before_after.png (before | after) and OUT/lips.csv.
//!
//!     cargo run --release -p validation --features studies --example lips_thin -- OUT [WIDTH] [SPP]

use glam::{Vec2, Vec3};
use render::material::{Material, SkinKnobs};
use render::renderer::{RenderOptions, render_with};
use render::scene::Scene;
use skin_fit::maps::{Eumelanin, Exposure, MapsModel, MapsOptions};
use skin_optics::color::LinearSrgb;
use skin_optics::lab::Lab;
use std::fmt::Write as _;
use std::path::PathBuf;

/// Distance of the camera from the lips' centre, mm.
const DISTANCE_MM: f32 = 250.0;
/// Half the width of the view at the lips, mm.
const HALF_VIEW_MM: f32 = 25.0;

fn scene_text(camera: &str, skin_keys: &str) -> String {
    format!(
        "{camera}\n[environment]\nspectrum = \"d65\"\nintensity = 1\n\
         [materials.skin]\ntype = \"skin\"\nalbedo_texture = \"builtin:Map-COL.jpg\"\n\
         fit_maps = \"auto-rgb\"\n{skin_keys}\n\
         [[meshes]]\nfile = \"builtin:LeePerrySmith.glb\"\nmaterial = \"skin\"\nunits_mm = 45\n\
         flip_v = true\n"
    )
}

fn lab(rgb: [f64; 3]) -> Lab {
    Lab::from_xyz(LinearSrgb(rgb).to_xyz())
}

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let out = PathBuf::from(args.next().unwrap_or_else(|| "out/lips".into()));
    let width: usize = args.next().map_or(Ok(160), |s| s.parse())?;
    let spp: u32 = args.next().map_or(Ok(64), |s| s.parse())?;
    std::fs::create_dir_all(&out)?;
    let knobs = SkinKnobs::default();
    let far = "[camera]\nposition_mm = [0, 0, 1000]\nlook_at_mm = [0, 0, 0]\nfov_deg = 20";
    let probe = Scene::from_toml(&scene_text(far, ""), "lips.toml", None, &knobs)?;
    let Material::Skin(skin) = &probe.materials[0] else {
        anyhow::bail!("the head is not skin");
    };
    let maps = skin.maps.as_ref().expect("fitted maps");
    let thin = maps.maps.thin().expect("thin texels on the lips");
    // The lips: thin texels as red as the vermilion (a* > 27, 40 < L* < 56 as given, the lips'
    // selection of BENCHMARKS.md "Chromophore maps"); the triangles whose centroid reads one,
    // their area-weighted centre and normal.
    let texture = &probe.textures[0];
    let (tw, th) = texture.size();
    let texel_of = |uv: Vec2| {
        let x = ((uv.x.rem_euclid(1.0) * tw as f32) as usize).min(tw - 1);
        let y = ((uv.y.clamp(0.0, 1.0) * th as f32) as usize).min(th - 1);
        y * tw + x
    };
    let lips: Vec<bool> = texture
        .texels()
        .iter()
        .enumerate()
        .map(|(i, t)| {
            let uv = Vec2::new(
                ((i % tw) as f32 + 0.5) / tw as f32,
                ((i / tw) as f32 + 0.5) / th as f32,
            );
            let l = lab(t.map(f64::from));
            thin.is_thin(uv) && l.a > 27.0 && l.l > 40.0 && l.l < 56.0
        })
        .collect();
    let centroid = |t: &[Vec3; 3]| (t[0] + t[1] + t[2]) / 3.0;
    let (mut centre, mut normal, mut area, mut count) = (Vec3::ZERO, Vec3::ZERO, 0.0f32, 0);
    for (t, uv) in probe.geometry.triangles_with_uvs_of(0) {
        let n = (t[1] - t[0]).cross(t[2] - t[0]);
        if n.z > 0.0 && lips[texel_of((uv[0] + uv[1] + uv[2]) / 3.0)] {
            let a = 0.5 * n.length();
            centre += a * centroid(&t);
            normal += 0.5 * n;
            area += a;
            count += 1;
        }
    }
    let (centre, normal) = (centre / area, normal.normalize());
    println!("lips: {count} triangles, {area:.0} mm² around {centre} facing {normal}");
    let eye = centre + normal * DISTANCE_MM;
    let fov = 2.0 * (HALF_VIEW_MM / DISTANCE_MM).atan().to_degrees();
    let camera = format!(
        "[camera]\nposition_mm = [{}, {}, {}]\nlook_at_mm = [{}, {}, {}]\nfov_deg = {fov}",
        eye.x, eye.y, eye.z, centre.x, centre.y, centre.z
    );
    let height = width * 3 / 4;
    let mut films = Vec::new();
    let mut csv = String::from(
        "case,load_cpu_s,render_cpu_s,cpu_us_per_sample,lip_pixels,r,g,b,L,a,b_star,de2000,de2000_same_L\n",
    );
    // The target: the texture's thin texels at the fit's exposure (the fit as `fit_maps` runs it).
    let opts = MapsOptions {
        eumelanin: Eumelanin::Fit,
        exposure: "auto-rgb".parse::<Exposure>().map_err(anyhow::Error::msg)?,
        cache_dir: skin_io::cache::cache_dir(),
        cache_max_bytes: skin_io::cache::max_bytes()?,
        ..MapsOptions::default()
    };
    let texels = probe.textures[0].texels();
    let fit = MapsModel::load(&opts)?.fit(texels, None, &opts, &|_| {})?;
    let gains = fit.summary.exposure;
    let flags = &fit.thin_epidermis.as_ref().expect("thin texels").texels;
    let (mut sum, mut n) = ([0.0f64; 3], 0usize);
    for (t, _) in texels
        .iter()
        .zip(flags)
        .zip(&lips)
        .filter(|((_, f), l)| **f && **l)
        .map(|(x, _)| x)
    {
        for c in 0..3 {
            sum[c] += f64::from(t[c]) * gains[c];
        }
        n += 1;
    }
    let target = sum.map(|s| s / n as f64);
    let target_lab = lab(target);
    println!(
        "texture's lips ({n} texels, gains {gains:.3?}): linear {target:.4?}, L* {:.1} a* {:.1} b* {:.1}",
        target_lab.l, target_lab.a, target_lab.b
    );
    let _ = writeln!(
        csv,
        "texture,,,,{n},{:.5},{:.5},{:.5},{:.2},{:.2},{:.2},0,0",
        target[0], target[1], target[2], target_lab.l, target_lab.a, target_lab.b
    );
    for (case, keys) in [("before", "thin_epidermis = false"), ("after", "")] {
        let load = cpu_time::ProcessTime::now();
        let scene = Scene::from_toml(&scene_text(&camera, keys), "lips.toml", None, &knobs)?;
        let load_s = load.elapsed().as_secs_f64();
        let opts = RenderOptions {
            width,
            height,
            spp,
            seed: 1,
            ..Default::default()
        };
        let settings = opts.validate()?;
        let body = render::integrator::BodyIntegrator::build(&scene, settings.integrator);
        let start = cpu_time::ProcessTime::now();
        let (film, _) = render_with(&scene, &body, &settings, None)?;
        let render_s = start.elapsed().as_secs_f64();
        // Lip pixels: the primary ray through the pixel's centre hits a thin texel.
        let aspect = width as f32 / height as f32;
        let (mut sum, mut k) = ([0.0f64; 3], 0usize);
        for y in 0..height {
            for x in 0..width {
                let ndc = Vec2::new(
                    (x as f32 + 0.5) / width as f32,
                    (y as f32 + 0.5) / height as f32,
                );
                let (o, d) = scene.camera.generate_ray(ndc, aspect, Vec2::ZERO);
                let Some(hit) = scene.geometry.intersect(o, d, 0.0, f32::INFINITY) else {
                    continue;
                };
                if hit.material == 0 && lips[texel_of(hit.uv)] {
                    let c = film.linear_srgb(x, y);
                    for i in 0..3 {
                        sum[i] += f64::from(c[i]);
                    }
                    k += 1;
                }
            }
        }
        let mean = sum.map(|s| s / k as f64);
        let l = lab(mean);
        let de = target_lab.delta_e_2000(l);
        let scale = target[1].max(1e-9) / mean[1].max(1e-9);
        let de_same_l = target_lab.delta_e_2000(lab(mean.map(|c| c * scale)));
        let per_sample_us = 1e6 * render_s / (width * height) as f64 / f64::from(spp);
        println!(
            "{case}: load {load_s:.1} CPU-s, render {render_s:.1} CPU-s ({per_sample_us:.1} µs per sample); \
             {k} lip pixels: linear {mean:.4?}, L* {:.1} a* {:.1} b* {:.1}; ΔE2000 {de:.1} (at the texture's luminance {de_same_l:.1})",
            l.l, l.a, l.b
        );
        let _ = writeln!(
            csv,
            "{case},{load_s:.2},{render_s:.2},{per_sample_us:.3},{k},{:.5},{:.5},{:.5},{:.2},{:.2},{:.2},{de:.2},{de_same_l:.2}",
            mean[0], mean[1], mean[2], l.l, l.a, l.b
        );
        films.push(film);
    }
    std::fs::write(out.join("lips.csv"), csv)?;
    let mut both = image::RgbImage::new(2 * width as u32, height as u32);
    for (i, film) in films.iter().enumerate() {
        let px = film.to_srgb8(0.0);
        for y in 0..height {
            for x in 0..width {
                let p = &px[3 * (y * width + x)..3 * (y * width + x) + 3];
                both.put_pixel(
                    (i * width + x) as u32,
                    y as u32,
                    image::Rgb([p[0], p[1], p[2]]),
                );
            }
        }
    }
    both.save(out.join("lips_before_after.png"))?;
    println!("wrote {}", out.display());
    Ok(())
}
