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
//!     cargo run --release -p validation --features studies --example hetero_head -- OUT [SPP_VOL] [SPP_BSSRDF]

use render::film::Film;
use render::integrator::{BodyIntegrator, IntegratorKind};
use render::material::SkinKnobs;
use render::renderer::{RenderOptions, render_with};
use render::scene::Scene;
use skin_plot::{LineChart, Panel, Series, render_rgb};
use std::fmt::Write as _;
use std::path::PathBuf;

/// Image side, pixels.
const SIDE: usize = 160;

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

/// The regions: the lit cheek (the head's left, right in the image), the lower lip's centre,
/// the right ear's lit rim (right of the image) and the forehead's centre.
const REGIONS: [Region; 4] = [
    Region {
        name: "cheek",
        x: [98, 108],
        y: [86, 98],
    },
    Region {
        name: "lip",
        x: [74, 86],
        y: [111, 116],
    },
    Region {
        name: "ear",
        x: [122, 127],
        y: [74, 90],
    },
    Region {
        name: "forehead",
        x: [68, 92],
        y: [32, 46],
    },
];

fn render(scene: &Scene, kind: IntegratorKind, spp: u32, seed: u64) -> anyhow::Result<(Film, f64)> {
    let start = cpu_time::ProcessTime::now();
    let body = BodyIntegrator::build(scene, kind);
    let opts = RenderOptions {
        width: SIDE,
        height: SIDE,
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

/// The film's tone-mapped pixels with the regions boxed in green.
fn boxed(film: &Film) -> Vec<u8> {
    let mut px = film.to_srgb8(0.0);
    for r in &REGIONS {
        for y in r.y[0] - 1..=r.y[1] {
            for x in r.x[0] - 1..=r.x[1] {
                let edge = y == r.y[0] - 1 || y == r.y[1] || x == r.x[0] - 1 || x == r.x[1];
                if edge {
                    px[(y * SIDE + x) * 3..(y * SIDE + x) * 3 + 3].copy_from_slice(&[0, 220, 0]);
                }
            }
        }
    }
    px
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
    let surfaces: &[(&str, &str)] = if std::env::var("SURFACES").is_ok_and(|v| v == "oily") {
        &[("oily", "")]
    } else {
        &[("oily", ""), ("smooth", "surface = \"smooth\"")]
    };
    for &(surface, key) in surfaces {
        let mut text = HEAD.replace("{surface}", key);
        if sky {
            let lights = text.find("[[lights]]").expect("the quad light");
            text.truncate(lights);
            text = text.replace("intensity = 0.01", "intensity = 1.0");
        }
        let scene = Scene::from_toml(&text, "hetero_head.toml", None, &SkinKnobs::default())?;
        let (bss, bss_cpu) = render(&scene, IntegratorKind::Bssrdf, spp_bss, 1)?;
        let (vol, vol_cpu) = render(&scene, IntegratorKind::Volumetric, spp_vol, 2)?;
        println!(
            "## {surface} surface: BSSRDF {spp_bss} spp ({bss_cpu:.1} CPU-s), walk {spp_vol} spp \
             ({vol_cpu:.1} CPU-s)"
        );
        println!("| region | pixels (x; y) | walk Y | BSSRDF Y | BSSRDF − walk |");
        println!("|---|---|---|---|---|");
        let mut diffs = Vec::new();
        for r in &REGIONS {
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
        images.push(boxed(&bss));
        images.push(boxed(&vol));
        bars.push((surface, diffs));
    }
    std::fs::write(out.join("hetero_head.csv"), csv)?;
    // The bars: per region i (x = 1..4: cheek, lip, ear, forehead), one bar per surface, side by
    // side, with a ±1σ whisker.
    let mut chart = LineChart::new(
        "BSSRDF against the walk, region means (1 cheek, 2 lip, 3 ear, 4 forehead)",
        "region",
        "difference (%)",
    )
    .with_x_range(0.4, 4.6);
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
    chart = chart.with_series(Series::dashed("", vec![(0.4, 0.0), (4.6, 0.0)]).with_color([0; 3]));
    // The images (BSSRDF and walk per surface: oily, then smooth), each twice its size,
    // above the chart.
    let scale = 2;
    let (w, ih, ch) = (images.len() * SIDE * scale, SIDE * scale, 500);
    let plot = render_rgb(&[Panel::Line(chart)], w as u32, ch as u32)?;
    let mut png = image::RgbImage::new(w as u32, (ih + ch) as u32);
    for (k, img) in images.iter().enumerate() {
        for y in 0..ih {
            for x in 0..SIDE * scale {
                let at = ((y / scale) * SIDE + x / scale) * 3;
                png.put_pixel(
                    (k * SIDE * scale + x) as u32,
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
    png.save(out.join("hetero_head.png"))?;
    println!(
        "images left to right: oily BSSRDF, oily walk, smooth BSSRDF, smooth walk; wrote {}",
        out.display()
    );
    Ok(())
}
