//! The built-in head with chromophore maps, BSSRDF against the volumetric walk (docs/physics.md
//! §19.4): the head (light skin, maps fitted to its texture as `skin maps --albedo
//! render/assets/Map-COL.jpg --exposure auto-rgb` does) seen from the front, 700 mm away, under a
//! D65 quad light up and to the right, with the default oily surface and with the smooth one
//! (which has no BSSRDF–walk gap of its own on uniform slabs, so what remains is the maps'). For
//! each: the mean luminance Y of four screen regions (written below, pixel rectangles of the
//! 160 × 160 image), both renders' noise, and their relative difference. The walk uses the local
//! majorant; both renders' CPU time is printed.
//!
//! Writes OUT/hetero_head.csv and OUT/hetero_head.png (the four images with the regions boxed,
//! and the differences as bars with ±1σ whiskers).
//!
//! With `LIGHT=sky` the quad light is replaced by a uniform D65 sky of luminance 1 (every exit of
//! the walk then sees the light, so its region means are far quieter), and `SURFACES=oily` keeps
//! only the default surface.
//!
//! With `VIEW=lip` the camera stays where it is and frames the lips closely (looking at y = 17
//! mm, fov 4°, 96 × 96 pixels, 0.51 mm a pixel at the lips): four regions of 200–700 pixels, the
//! lower lip's centre and the upper lip's (thin epidermis throughout), the full view's lip box
//! seen from here (the lower lip's lower edge, where the thin epidermis gives way to the normal
//! one, and the skin below it) and the chin. Writes OUT/hetero_head_lip_VARIANT.{csv,png}, where
//! `VARIANT` (that view only; the full view renders the maps) changes the skin:
//! `maps` (default), `thick` (scene key `thin_epidermis = false`: every texel under the
//! material's epidermis), `fine` (the grids refined to `map_profile_error = 0.005` and
//! `map_incidence_error = 0.002`), `planar` (`Curvature::Planar`: no curvature term), `uniform` (no maps:
//! the scalar skin of the median texel of region `UNIFORM_FROM`, 0 = the lower lip by default,
//! under the thin epidermis where that texel is thin: the geometry alone), `uniform-planar`
//! (both), `uniform-typical-kappa` and `uniform-typical-incidence` (that scalar skin with the
//! curvature gain κ(λ), or the oblique-incidence gain, of the maps' typical skin, the one skin
//! the material reads them from). With SPP_VOL = 0 only the BSSRDF renders: its image at four
//! times its size with the regions boxed, and per pixel row which pixels see thin-epidermis
//! texels and their C_h (to place the regions).
//!
//!     cargo run --release -p validation --features studies --example hetero_head -- OUT [SPP_VOL] [SPP_BSSRDF]

use render::bssrdf::Curvature;
use render::film::Film;
use render::integrator::{BodyIntegrator, IntegratorKind};
use render::material::{Material, SkinKnobs, SkinMaterial};
use render::renderer::{RenderOptions, render_with};
use render::scene::Scene;
use skin_plot::{LineChart, Panel, Series, render_rgb};
use std::fmt::Write as _;
use std::path::PathBuf;

/// Image side of the full view, pixels.
const SIDE: usize = 160;

/// Image side of the lips' view, pixels.
const LIP_SIDE: usize = 96;

/// The scene; `{surface}` is replaced by the skin's surface key.
const HEAD: &str = r#"
[camera]
position_mm = [0, 60, 700]
look_at_mm = [0, 60, 0]
fov_deg = 22

[environment]
spectrum = "d65"
intensity = 0.01

[materials.light]
type = "skin"
albedo_texture = "builtin:Map-COL.jpg"
fit_maps = "auto-rgb"
{surface}

[[meshes]]
file = "builtin:LeePerrySmith.glb"
material = "light"
units_mm = 45
flip_v = true

[[lights]]
type = "quad"
center_mm = [500, 400, 800]
look_at_mm = [0, 50, 0]
size_mm = [400, 400]
spectrum = "d65"
intensity = 20
"#;

/// A screen region: name and pixel rectangle [x0, x1) × [y0, y1) (x right, y down).
struct Region {
    name: &'static str,
    x: [usize; 2],
    y: [usize; 2],
}

/// The region `name` over pixels x ∈ [x₀, x₁), y ∈ [y₀, y₁).
const fn region(name: &'static str, x: [usize; 2], y: [usize; 2]) -> Region {
    Region { name, x, y }
}

/// The view: the camera's look-at point and field of view, the image side and the regions.
struct View {
    look_at_y_mm: f32,
    fov_deg: f32,
    side: usize,
    regions: &'static [Region],
}

/// The regions of the lips' view: the lower lip's centre (thin epidermis throughout), the upper
/// lip's (thin), the full view's "lip" box seen from here (the lower lip's lower edge, where the
/// thin epidermis gives way to the normal one, and the skin below it) and the chin's skin (normal
/// epidermis).
const LIP_REGIONS: [Region; 4] = [
    region("lower lip", [24, 65], [59, 67]),
    region("upper lip", [20, 60], [42, 53]),
    region("lip edge", [28, 68], [67, 84]),
    region("chin", [30, 62], [84, 95]),
];

/// The regions: the lit cheek (the head's left, right in the image), the lower lip's centre,
/// the right ear's lit rim (right of the image) and the forehead's centre.
const REGIONS: [Region; 4] = [
    region("cheek", [98, 108], [86, 98]),
    region("lip", [74, 86], [111, 116]),
    region("ear", [122, 127], [74, 90]),
    region("forehead", [68, 92], [32, 46]),
];

fn render(
    scene: &Scene,
    kind: IntegratorKind,
    side: usize,
    spp: u32,
    seed: u64,
) -> anyhow::Result<(Film, f64)> {
    let start = cpu_time::ProcessTime::now();
    let body = BodyIntegrator::build(scene, kind);
    let opts = RenderOptions {
        width: side,
        height: side,
        spp,
        seed,
        ..Default::default()
    };
    let film = render_with(scene, &body, &opts.validate()?, None)?.0;
    Ok((film, start.elapsed().as_secs_f64()))
}

/// Mean luminance Y over the region and its standard error (the pixels' variances).
fn mean(film: &Film, r: &Region) -> (f64, f64) {
    let (mut s, mut v, mut n) = (0.0, 0.0, 0.0);
    for y in r.y[0]..r.y[1] {
        for x in r.x[0]..r.x[1] {
            s += f64::from(film.xyz(x, y)[1]);
            v += film.variance(x, y);
            n += 1.0;
        }
    }
    (s / n, v.sqrt() / n)
}

/// The film's tone-mapped pixels with the view's regions boxed in green.
fn boxed(film: &Film, view: &View) -> Vec<u8> {
    let side = view.side;
    let mut px = film.to_srgb8(0.0);
    for r in view.regions {
        for y in r.y[0] - 1..=r.y[1] {
            for x in r.x[0] - 1..=r.x[1] {
                let edge = y == r.y[0] - 1 || y == r.y[1] || x == r.x[0] - 1 || x == r.x[1];
                if edge {
                    px[(y * side + x) * 3..(y * side + x) * 3 + 3].copy_from_slice(&[0, 220, 0]);
                }
            }
        }
    }
    px
}

/// How the lips' view changes the skin (`VARIANT`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Variant {
    /// The maps as the scene fits them.
    Maps,
    /// The maps with `thin_epidermis = false`.
    Thick,
    /// The maps with finer grids: `map_profile_error = 0.005`, `map_incidence_error = 0.002`.
    Fine,
    /// The maps without the curvature term.
    Planar,
    /// The lower lip's median texel as a scalar skin.
    Uniform,
    /// That scalar skin without the curvature term.
    UniformPlanar,
    /// That scalar skin with the curvature gain κ(λ) of the maps' typical skin (what the maps'
    /// BSSRDF applies at every texel).
    UniformTypicalKappa,
    /// That scalar skin with the oblique-incidence gain of the maps' typical skin.
    UniformTypicalIncidence,
}

impl Variant {
    fn from_env() -> anyhow::Result<Self> {
        Ok(match std::env::var("VARIANT").as_deref() {
            Err(_) | Ok("maps") => Self::Maps,
            Ok("thick") => Self::Thick,
            Ok("fine") => Self::Fine,
            Ok("planar") => Self::Planar,
            Ok("uniform") => Self::Uniform,
            Ok("uniform-planar") => Self::UniformPlanar,
            Ok("uniform-typical-kappa") => Self::UniformTypicalKappa,
            Ok("uniform-typical-incidence") => Self::UniformTypicalIncidence,
            Ok(v) => anyhow::bail!(
                "VARIANT '{v}' unknown (valid: maps, thick, fine, planar, uniform, uniform-planar, \
                 uniform-typical-kappa, uniform-typical-incidence)"
            ),
        })
    }

    fn name(self) -> &'static str {
        match self {
            Self::Maps => "maps",
            Self::Thick => "thick",
            Self::Fine => "fine",
            Self::Planar => "planar",
            Self::Uniform => "uniform",
            Self::UniformPlanar => "uniform-planar",
            Self::UniformTypicalKappa => "uniform-typical-kappa",
            Self::UniformTypicalIncidence => "uniform-typical-incidence",
        }
    }

    fn is_uniform(self) -> bool {
        matches!(
            self,
            Self::Uniform
                | Self::UniformPlanar
                | Self::UniformTypicalKappa
                | Self::UniformTypicalIncidence
        )
    }
}

/// The scene's skin replaced by the scalar skin of the median texel (each parameter's median)
/// seen in region `r` of the view, under the thin epidermis when most of those texels are thin;
/// with `variant` it takes the maps' typical skin's curvature gain or oblique-incidence gain
/// instead of its own. Returns the texel's (C_m, β_m, C_h, epidermis mm).
fn uniform_skin(
    scene: &mut Scene,
    view: &View,
    r: &Region,
    knobs: &SkinKnobs,
    variant: Variant,
) -> anyhow::Result<[f32; 4]> {
    let Material::Skin(skin) = &scene.materials[0] else {
        anyhow::bail!("the head's material is not skin");
    };
    let maps = skin.maps.as_ref().expect("the head's maps");
    let (mut values, mut thin) = ([Vec::new(), Vec::new(), Vec::new(), Vec::new()], 0usize);
    for y in r.y[0]..r.y[1] {
        for x in r.x[0]..r.x[1] {
            let ndc = glam::Vec2::new(
                (x as f32 + 0.5) / view.side as f32,
                (y as f32 + 0.5) / view.side as f32,
            );
            let (o, d) = scene.camera.generate_ray(ndc, 1.0, glam::Vec2::ZERO);
            let Some(hit) = scene.geometry.intersect(o, d, 0.0, f32::INFINITY) else {
                continue;
            };
            let p = maps.maps.at(hit.uv);
            for k in 0..3 {
                values[k].push(p[k]);
            }
            let e = maps.epidermis_at_mm(hit.uv);
            values[3].push(e);
            thin += usize::from(e < maps.epidermis_mm);
        }
    }
    let median = |v: &mut Vec<f32>| {
        v.sort_by(f32::total_cmp);
        v[v.len() / 2]
    };
    let p: [f32; 4] = std::array::from_fn(|k| median(&mut values[k]));
    let seen = values[0].len();
    println!(
        "{}: {seen} texels, {thin} thin; the maps' typical skin: C_m {:.4}, C_h {:.4}",
        r.name,
        skin.params.melanin(),
        skin.params.hemoglobin()
    );
    let params = skin
        .params
        .with_melanin(f64::from(p[0]))?
        .with_eumelanin_blend(f64::from(p[1]))?
        .with_hemoglobin(f64::from(p[2]))?
        .with_epidermis_thickness_mm(f64::from(p[3]))?;
    let mut built = SkinMaterial::build(params, skin.surface.roughness(), None, knobs)?;
    // The maps' typical skin as a scalar material: what the maps' BSSRDF reads its one skin from.
    let typical = SkinMaterial::build(skin.params, skin.surface.roughness(), None, knobs)?;
    let (own, typical_ss) = (
        built.subsurface.as_mut().expect("a BSSRDF"),
        typical.subsurface.as_ref().expect("a BSSRDF"),
    );
    if let (Some(k_own), Some(k_typ)) = (&own.curvature, &typical_ss.curvature) {
        for nm in [450.0, 500.0, 550.0, 600.0, 650.0] {
            println!(
                "κ at {nm} nm: this skin {:.3} mm⁻¹, the typical skin {:.3} mm⁻¹",
                k_own.kappa_per_mm(nm),
                k_typ.kappa_per_mm(nm)
            );
        }
    }
    match variant {
        Variant::UniformTypicalKappa => own.curvature.clone_from(&typical_ss.curvature),
        Variant::UniformTypicalIncidence => {
            own.directional = typical_ss.directional.clone();
            built.directional = typical.directional.clone();
        }
        _ => {}
    }
    scene.materials[0] = Material::Skin(built);
    Ok(p)
}

/// Prints, per row of the view, which pixels see thin-epidermis texels (`#`), and their C_h as
/// the digit ⌊40 C_h⌋ (at most 9).
fn texel_chart(scene: &Scene, view: &View) {
    let Material::Skin(skin) = &scene.materials[0] else {
        return;
    };
    let Some(maps) = skin.maps.as_ref() else {
        return;
    };
    for y in 0..view.side {
        let mut line = String::new();
        let mut ch = String::new();
        for x in 0..view.side {
            let ndc = glam::Vec2::new(
                (x as f32 + 0.5) / view.side as f32,
                (y as f32 + 0.5) / view.side as f32,
            );
            let (o, d) = scene.camera.generate_ray(ndc, 1.0, glam::Vec2::ZERO);
            match scene.geometry.intersect(o, d, 0.0, f32::INFINITY) {
                Some(hit) => {
                    line.push(if maps.epidermis_at_mm(hit.uv) < maps.epidermis_mm {
                        '#'
                    } else {
                        '.'
                    });
                    let c = maps.maps.at(hit.uv)[2];
                    ch.push(char::from_digit(((c * 40.0) as u32).min(9), 10).unwrap_or('?'));
                }
                None => {
                    line.push(' ');
                    ch.push(' ');
                }
            }
        }
        println!("{y:3} {line}  {ch}");
    }
}

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let out = PathBuf::from(args.next().unwrap_or_else(|| "out/hetero_head".into()));
    let spp_vol: u32 = args.next().map_or(Ok(128), |s| s.parse())?;
    let spp_bss: u32 = args.next().map_or(Ok(64), |s| s.parse())?;
    std::fs::create_dir_all(&out)?;
    let mut csv = String::from(
        "surface,region,x0,x1,y0,y1,bssrdf,bssrdf_se,volumetric,volumetric_se,difference,difference_se\n",
    );
    let mut images = Vec::new();
    let mut bars = Vec::new();
    let sky = std::env::var("LIGHT").is_ok_and(|v| v == "sky");
    let lip = std::env::var("VIEW").is_ok_and(|v| v == "lip");
    let view = if lip {
        View {
            look_at_y_mm: 17.0,
            fov_deg: 4.0,
            side: LIP_SIDE,
            regions: &LIP_REGIONS,
        }
    } else {
        View {
            look_at_y_mm: 60.0,
            fov_deg: 22.0,
            side: SIDE,
            regions: &REGIONS,
        }
    };
    let variant = Variant::from_env()?;
    anyhow::ensure!(
        lip || variant == Variant::Maps,
        "VARIANT needs VIEW=lip (the full view renders the maps only)"
    );
    let knobs = SkinKnobs {
        curvature: if matches!(variant, Variant::Planar | Variant::UniformPlanar) {
            Curvature::Planar
        } else {
            Curvature::FirstOrder
        },
        ..SkinKnobs::default()
    };
    let surfaces: &[(&str, &str)] = if std::env::var("SURFACES").is_ok_and(|v| v == "oily") {
        &[("oily", "")]
    } else {
        &[("oily", ""), ("smooth", "surface = \"smooth\"")]
    };
    for &(surface, key) in surfaces {
        let mut text = HEAD.replace("{surface}", key);
        let extra = match variant {
            Variant::Thick => "\nthin_epidermis = false",
            Variant::Fine => "\nmap_profile_error = 0.005\nmap_incidence_error = 0.002",
            _ => "",
        };
        text = text.replace(
            "fit_maps = \"auto-rgb\"",
            &format!("fit_maps = \"auto-rgb\"{extra}"),
        );
        if sky {
            let lights = text.find("[[lights]]").expect("the quad light");
            text.truncate(lights);
            text = text.replace("intensity = 0.01", "intensity = 1.0");
        }
        if lip {
            text = text
                .replace(
                    "look_at_mm = [0, 60, 0]",
                    &format!("look_at_mm = [0, {}, 0]", view.look_at_y_mm),
                )
                .replace("fov_deg = 22", &format!("fov_deg = {}", view.fov_deg));
        }
        let mut scene = Scene::from_toml(&text, "hetero_head.toml", None, &knobs)?;
        if variant.is_uniform() {
            let from = std::env::var("UNIFORM_FROM").map_or(Ok(0), |s| s.parse::<usize>())?;
            let region = view
                .regions
                .get(from)
                .ok_or_else(|| anyhow::anyhow!("UNIFORM_FROM {from} beyond the regions"))?;
            let p = uniform_skin(&mut scene, &view, region, &knobs, variant)?;
            println!(
                "uniform skin: C_m {:.4}, β_m {:.3}, C_h {:.4}, epidermis {} mm",
                p[0], p[1], p[2], p[3]
            );
        }
        let (bss, bss_cpu) = render(&scene, IntegratorKind::Bssrdf, view.side, spp_bss, 1)?;
        if spp_vol == 0 {
            texel_chart(&scene, &view);
            // The BSSRDF's image alone, four times its size (to place the regions).
            let (px, side) = (boxed(&bss, &view), view.side);
            let big = image::RgbImage::from_fn(4 * side as u32, 4 * side as u32, |x, y| {
                let at = ((y as usize / 4) * side + x as usize / 4) * 3;
                image::Rgb([px[at], px[at + 1], px[at + 2]])
            });
            big.save(out.join("hetero_head_bssrdf.png"))?;
            println!("BSSRDF only ({bss_cpu:.1} CPU-s); wrote {}", out.display());
            return Ok(());
        }
        let (vol, vol_cpu) = render(&scene, IntegratorKind::Volumetric, view.side, spp_vol, 2)?;
        println!(
            "## {surface} surface{}: BSSRDF {spp_bss} spp ({bss_cpu:.1} CPU-s), walk {spp_vol} spp \
             ({vol_cpu:.1} CPU-s)",
            if lip {
                format!(", {}", variant.name())
            } else {
                String::new()
            }
        );
        println!("| region | pixels (x; y) | walk Y | BSSRDF Y | BSSRDF − walk |");
        println!("|---|---|---|---|---|");
        let mut diffs = Vec::new();
        for r in view.regions {
            let (v, vs) = mean(&vol, r);
            let (b, bs) = mean(&bss, r);
            let d = b / v - 1.0;
            let ds = (bs / v).hypot(b * vs / (v * v));
            println!(
                "| {} | {}–{}; {}–{} | {v:.5} ± {vs:.5} | {b:.5} ± {bs:.5} | {:+.1}% ± {:.1}% |",
                r.name,
                r.x[0],
                r.x[1] - 1,
                r.y[0],
                r.y[1] - 1,
                100.0 * d,
                100.0 * ds
            );
            let _ = writeln!(
                csv,
                "{surface},{},{},{},{},{},{b:.6},{bs:.6},{v:.6},{vs:.6},{d:.5},{ds:.5}",
                r.name, r.x[0], r.x[1], r.y[0], r.y[1]
            );
            diffs.push((100.0 * d, 100.0 * ds));
        }
        images.push(boxed(&bss, &view));
        images.push(boxed(&vol, &view));
        bars.push((surface, diffs));
    }
    let stem = if lip {
        format!("hetero_head_lip_{}", variant.name())
    } else {
        "hetero_head".to_string()
    };
    std::fs::write(out.join(format!("{stem}.csv")), csv)?;
    // The bars: per region i (x = 1, 2, …, in the view's order), one bar per surface, side by
    // side, with a ±1σ whisker.
    let names: Vec<String> = view
        .regions
        .iter()
        .enumerate()
        .map(|(i, r)| format!("{} {}", i + 1, r.name))
        .collect();
    let x_hi = view.regions.len() as f64 + 0.6;
    let mut chart = LineChart::new(
        format!("BSSRDF − walk ({})", names.join(", ")),
        "region",
        "difference (%)",
    )
    .with_x_range(0.4, x_hi);
    for (k, (surface, diffs)) in bars.iter().enumerate() {
        let color = skin_plot::palette_color(k);
        let offset = if k == 0 { -0.3 } else { 0.02 };
        for (i, &(d, ds)) in diffs.iter().enumerate() {
            let x0 = (i + 1) as f64 + offset;
            let x1 = x0 + 0.28;
            let name = if i == 0 {
                format!("{surface} surface")
            } else {
                String::new()
            };
            chart = chart.with_series(
                Series::line(name, vec![(x0, 0.0), (x0, d), (x1, d), (x1, 0.0)]).with_color(color),
            );
            let xm = 0.5 * (x0 + x1);
            chart = chart.with_series(
                Series::line("", vec![(xm, d - ds), (xm, d + ds)]).with_color([0, 0, 0]),
            );
        }
    }
    chart = chart.with_series(Series::dashed("", vec![(0.4, 0.0), (x_hi, 0.0)]).with_color([0; 3]));
    // The images (BSSRDF and walk per surface: oily, then smooth), each twice its size,
    // above the chart.
    let side = view.side;
    let scale = if lip { 3 } else { 2 };
    let (w, ih, ch) = (images.len() * side * scale, side * scale, 500);
    let plot = render_rgb(&[Panel::Line(chart)], w as u32, ch as u32)?;
    let mut png = image::RgbImage::new(w as u32, (ih + ch) as u32);
    for (k, img) in images.iter().enumerate() {
        for y in 0..ih {
            for x in 0..side * scale {
                let at = ((y / scale) * side + x / scale) * 3;
                png.put_pixel(
                    (k * side * scale + x) as u32,
                    y as u32,
                    image::Rgb([img[at], img[at + 1], img[at + 2]]),
                );
            }
        }
    }
    for y in 0..ch {
        for x in 0..w {
            let at = (y * w + x) * 3;
            png.put_pixel(
                x as u32,
                (ih + y) as u32,
                image::Rgb([plot[at], plot[at + 1], plot[at + 2]]),
            );
        }
    }
    png.save(out.join(format!("{stem}.png")))?;
    println!(
        "images left to right: oily BSSRDF, oily walk, smooth BSSRDF, smooth walk; wrote {}",
        out.display()
    );
    Ok(())
}
