//! The BSSRDF against the volumetric walk on curved skin (docs/physics.md §8.1,
//! docs/accuracy_evidence.md §3): spheres and tilted slabs at one wavelength under a uniform sky
//! (or a lamp), smooth surface, g = 0; prints each region's means and the BSSRDF's error.
//!
//! `cargo run --release -p render --features studies --example curved_gap -- RADIUS|slab|angles
//! [BSSRDF_SPP] [WALK_SPP]`; environment: `SKIN` (the material's keys; default C_m 0.05, β_m 0.7,
//! C_h 0.02), `NM` (comma-separated wavelengths), `INC=normal` (the former angular factor),
//! `LIGHT=1` (a sphere lamp and no sky), `CURV=planar` (no curvature term). Walk renders are kept
//! in `CG_DIR` (default /tmp/cg) and reused.
use glam::Vec2;
use render::film::Film;
use render::integrator::{BodyIntegrator, IntegratorKind};
use render::material::SkinKnobs;
use render::renderer::{RenderOptions, render_with};
use render::scene::{Hit, Scene};
use render::volumetric::shapes::box_obj;

fn region(scene: &Scene, side: usize, keep: impl Fn(glam::Vec3) -> bool) -> Vec<usize> {
    (0..side * side)
        .filter(|&i| {
            let (x, y) = (i % side, i / side);
            let (o, d) = render::testing::pixel_ray(scene, side, x, y);
            matches!(scene.intersect(o, d, 0.0, f32::INFINITY), Some(Hit::Surface(si)) if keep(si.p))
        })
        .collect()
}

fn mean(film: &Film, px: &[usize], side: usize) -> (f64, f64) {
    let (mut s, mut v) = (0.0, 0.0);
    for &i in px {
        s += f64::from(film.xyz(i % side, i / side)[1]);
        v += film.variance(i % side, i / side);
    }
    let n = px.len() as f64;
    (s / n, v.sqrt() / n)
}

/// Where the planar BSSRDF's energy goes on a sphere of radius `r` (mm) under the uniform sky
/// at `nm`: the closed form of the separable model there (surface F plus T a R_tot per pixel, 4×4
/// rays per pixel of the 0.9-radius region; what the BSSRDF must render if probes, fallback,
/// axis MIS and the area measure lose nothing), the profile's energy beyond √2 R and 2R (the
/// exits facing away, and the fallback), and the first-order curvature gain the term adds on
/// this sphere, κ ∫ d²/2R R(d) 2πd dd over d < √2 R, against its plane value κ ⟨d²⟩ / 2R.
fn budget(scene: &Scene, side: usize, r: f32, nm: f32) {
    let render::material::Material::Skin(skin) = &scene.materials[0] else {
        return;
    };
    let Some(ss) = &skin.subsurface else { return };
    let (table, dir) = (&ss.table, &ss.directional);
    let r_tot = f64::from(table.total(nm));
    let px = region(scene, side, |p| p.truncate().length() / r < 0.9);
    let (mut sum, k) = (0.0, 4);
    for &i in &px {
        for j in 0..k * k {
            let ndc = Vec2::new(
                ((i % side) as f32 + ((j % k) as f32 + 0.5) / k as f32) / side as f32,
                ((i / side) as f32 + ((j / k) as f32 + 0.5) / k as f32) / side as f32,
            );
            let (o, d) = scene.camera.generate_ray(ndc, 1.0, Vec2::ZERO);
            if let Some(Hit::Surface(si)) = scene.intersect(o, d, 0.0, f32::INFINITY) {
                let mu = (-d).dot(si.ns).clamp(0.0, 1.0);
                let t = f64::from(dir.transmittance(mu));
                sum += (1.0 - t) + f64::from(dir.factor(mu, nm)) * r_tot;
            }
        }
    }
    let closed = sum / (px.len() * k * k) as f64;
    let kappa = ss
        .curvature
        .as_ref()
        .map_or(0.0, |c| f64::from(c.kappa_per_mm(nm)));
    let (n, r_max) = (20_000, f64::from(table.r_max_mm(nm)));
    let (mut beyond_hemi, mut beyond_2r, mut m2_hemi, mut m2_all) = (0.0, 0.0, 0.0, 0.0);
    let rr = f64::from(r);
    for i in 0..n {
        let d = (i as f64 + 0.5) / n as f64 * r_max;
        let e = f64::from(table.eval(nm, d as f32)) * 2.0 * std::f64::consts::PI * d * r_max
            / n as f64
            / r_tot;
        m2_all += e * d * d;
        if d > std::f64::consts::SQRT_2 * rr {
            beyond_hemi += e;
        } else {
            m2_hemi += e * d * d;
        }
        if d > 2.0 * rr {
            beyond_2r += e;
        }
    }
    println!(
        "sphere r {r} nm {nm} budget: closed form of the planar model {closed:.5} (R_tot {r_tot:.4}); \
         energy beyond √2R {:.2}%, beyond 2R {:.2}%; κ {kappa:.3}/mm, ⟨d²⟩ {m2_all:.3} mm²; \
         first-order gain on this sphere {:+.2}% of R_tot (plane value {:+.2}%)",
        100.0 * beyond_hemi,
        100.0 * beyond_2r,
        100.0 * kappa * m2_hemi / (2.0 * rr),
        100.0 * kappa * m2_all / (2.0 * rr),
    );
}

fn knobs() -> SkinKnobs {
    SkinKnobs {
        incidence: if std::env::var("INC").is_ok_and(|v| v == "normal") {
            render::bssrdf::Incidence::Normal
        } else {
            render::bssrdf::Incidence::AddingDoubling
        },
        curvature: if std::env::var("CURV").is_ok_and(|v| v == "planar") {
            render::bssrdf::Curvature::Planar
        } else {
            render::bssrdf::Curvature::FirstOrder
        },
        ..SkinKnobs::default()
    }
}

/// Volumetric film cached on disk by key (the walk does not depend on the BSSRDF's knobs).
fn vol(scene: &Scene, side: usize, spp: u32, nm: f32, key: &str) -> Film {
    let dir = std::env::var("CG_DIR").unwrap_or("/tmp/cg".into());
    let _ = std::fs::create_dir_all(&dir);
    let f = format!("{dir}/vol-{key}-{side}-{spp}-{nm}.txt");
    if let Ok(t) = std::fs::read_to_string(&f) {
        let v: Vec<f64> = t.split_whitespace().map(|x| x.parse().unwrap()).collect();
        let means = (0..side * side).map(|i| [v[2 * i]; 3]).collect();
        let var = (0..side * side).map(|i| v[2 * i + 1]).collect();
        return Film::from_means(side, side, means, var, spp);
    }
    let film = run(scene, IntegratorKind::Volumetric, side, spp, nm);
    let mut t = String::new();
    for i in 0..side * side {
        t += &format!(
            "{:e} {:e}\n",
            film.xyz(i % side, i / side)[1],
            film.variance(i % side, i / side)
        );
    }
    std::fs::write(&f, t).unwrap();
    film
}

fn run(scene: &Scene, kind: IntegratorKind, side: usize, spp: u32, nm: f32) -> Film {
    let body = BodyIntegrator::build(scene, kind);
    let opts = RenderOptions {
        width: side,
        height: side,
        spp,
        seed: 1,
        wavelength_nm: Some(nm),
        ..Default::default()
    };
    render_with(scene, &body, &opts.validate().unwrap(), None)
        .unwrap()
        .0
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let what = args.get(1).map_or("slab", String::as_str);
    let spp: u32 = args.get(2).map_or(64, |s| s.parse().unwrap());
    let vspp: u32 = args.get(3).map_or(64, |s| s.parse().unwrap());
    let skin = std::env::var("SKIN")
        .unwrap_or("melanin = 0.05\neumelanin = 0.7\nhemoglobin = 0.02".into());
    let keys = format!("{skin}\nsurface = \"smooth\"\nphase_g = 0");
    let dir = tempfile::tempdir().unwrap();
    let nms: Vec<f32> = std::env::var("NM")
        .unwrap_or("450,550,650".into())
        .split(',')
        .map(|s| s.parse().unwrap())
        .collect();
    if what == "angles" {
        use multipole::exact::adding_doubling::{AddingDoublingOptions, reflectance_by_angle};
        let params = skin_optics::SkinParams::new(0.05, 0.7, 0.02, 0.25).unwrap();
        let g: f64 = std::env::var("G").map_or(0.0, |s| s.parse().unwrap());
        for &nm in &nms {
            let m = multipole::LayeredMedium::skin(
                &params,
                skin_optics::Wavelength::new(f64::from(nm)).unwrap(),
                g,
            )
            .unwrap();
            let rows =
                reflectance_by_angle(&m, &AddingDoublingOptions::new(24, g).unwrap()).unwrap();
            let r1 = rows.last().unwrap().per_entering();
            for r in &rows {
                println!(
                    "{nm} mu_out {:.3} (θ {:.1}°) F {:.4} Rd/entering {:.5} ratio {:.4}",
                    r.mu_outside,
                    r.mu_outside.acos().to_degrees(),
                    r.totals.specular_reflectance,
                    r.per_entering(),
                    r.per_entering() / r1
                );
            }
        }
        return;
    }
    if what == "slab" {
        std::fs::write(dir.path().join("box.obj"), box_obj([200.0, 200.0, 40.0])).unwrap();
        for tilt in [0.0f32, 30.0, 50.0, 64.0] {
            let text = format!(
                "[camera]\nposition_mm = [0, 0, 400]\nlook_at_mm = [0, 0, 0]\nfov_deg = 1\n\
                 [environment]\nspectral_radiance = 1\n\
                 [materials.skin]\ntype = \"skin\"\n{keys}\n\
                 [[meshes]]\nfile = \"box.obj\"\nmaterial = \"skin\"\nrotate_deg = [{tilt}, 0, 0]\n"
            );
            let scene = Scene::from_toml(&text, "box.toml", Some(dir.path()), &knobs()).unwrap();
            let side = 4;
            let px: Vec<usize> = (0..side * side).collect();
            for &nm in &nms {
                let b = mean(
                    &run(&scene, IntegratorKind::Bssrdf, side, spp, nm),
                    &px,
                    side,
                );
                let v = mean(
                    &vol(&scene, side, vspp, nm, &format!("slab{tilt}{}", skin.len())),
                    &px,
                    side,
                );
                println!(
                    "slab tilt {tilt} nm {nm}: bssrdf {:.5}±{:.5} vol {:.5}±{:.5} gap {:+.2}% ± {:.2}",
                    b.0,
                    b.1,
                    v.0,
                    v.1,
                    100.0 * (b.0 / v.0 - 1.0),
                    100.0 * (b.1.hypot(v.1)) / v.0
                );
            }
        }
    } else {
        let r: f32 = what.parse().unwrap();
        let text = format!(
            "[camera]\nposition_mm = [0, 0, {}]\nlook_at_mm = [0, 0, 0]\nfov_deg = 11\n\
             {}[materials.skin]\ntype = \"skin\"\n{keys}\n\
             [[meshes]]\nshape = \"sphere\"\nmaterial = \"skin\"\nunits_mm = {r}\n{}",
            12.0 * r,
            if std::env::var("LIGHT").is_ok_and(|v| !v.is_empty()) {
                ""
            } else {
                "[environment]\nspectral_radiance = 1\n"
            },
            if std::env::var("LIGHT").is_ok_and(|v| !v.is_empty()) {
                "[[lights]]\ntype = \"sphere\"\ncenter_mm = [300, 150, 300]\nradius_mm = 60\nintensity = 20\n"
            } else {
                ""
            }
        );
        let scene = Scene::from_toml(&text, "s.toml", None, &knobs()).unwrap();
        let side = 24;
        let rings: Vec<(f32, f32)> =
            vec![(0.0, 0.9), (0.0, 0.3), (0.3, 0.6), (0.6, 0.8), (0.8, 0.9)];
        for &nm in &nms {
            if std::env::var("LIGHT").map_or(true, |v| v.is_empty()) {
                budget(&scene, side, r, nm);
            }
            let bf = run(&scene, IntegratorKind::Bssrdf, side, spp, nm);
            let vf = vol(
                &scene,
                side,
                vspp,
                nm,
                &format!(
                    "sphere{r}-{}-{}",
                    skin.replace(['\n', ' ', '"', '='], ""),
                    std::env::var("LIGHT").is_ok_and(|v| !v.is_empty())
                ),
            );
            for &(a, b) in &rings {
                let px = region(&scene, side, |p| {
                    let q = p.truncate().length() / r;
                    q >= a && q < b
                });
                let bm = mean(&bf, &px, side);
                let vm = mean(&vf, &px, side);
                println!(
                    "sphere r {r} nm {nm} ring {a}-{b} ({} px): bssrdf {:.5}±{:.5} vol {:.5}±{:.5} gap {:+.2}% ± {:.2}",
                    px.len(),
                    bm.0,
                    bm.1,
                    vm.0,
                    vm.1,
                    100.0 * (bm.0 / vm.0 - 1.0),
                    100.0 * (bm.1.hypot(vm.1)) / vm.0
                );
            }
        }
    }
}
