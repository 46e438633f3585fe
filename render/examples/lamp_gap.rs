//! The BSSRDF against the volumetric walk on thick, flat skin under a small lamp
//! (docs/accuracy_evidence.md §7): a 60 × 60 × 20 mm box of light skin, seen at 45° from 300 mm,
//! lit by the ear's back light (a 25-mm blackbody sphere, 230 mm away) at incidence θ_i and at
//! azimuth φ from the camera's (180°: the lamp opposite the camera, as behind the ear; 0°: beside
//! it). Per case: the frame's mean luminance of each integrator with its standard error (variance
//! pass), the BSSRDF's error against the walk, and the CPU seconds.
//!
//! `cargo run --release -p render --features studies --example lamp_gap -- SIDE SPP REF_SPP
//! [THETA_DEG,...] [PHI_DEG,...]`; environment: `SURFACE` (`smooth` (default) or `oily`), `NM` (one
//! wavelength, nm; default the full spectrum), `PRESET` (default `light`), `CAM_DEG` (the camera's
//! angle from the normal, default 45), `DEPTH` (paths of at most that many surface hits; the walk
//! one more), `LAMP_SCALE` (`ear`: the back light's radius × k, luminance ÷ k²). "Lobe" is
//! `Azimuth::Harmonics`, "separable" the default.

use render::bssrdf::Azimuth;
use render::integrator::{BodyIntegrator, IntegratorKind};
use render::material::SkinKnobs;
use render::renderer::{RenderOptions, render_with};
use render::scene::Scene;

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let num = |i: usize, d: u32| args.get(i).and_then(|s| s.parse().ok()).unwrap_or(d);
    let (side, spp, ref_spp) = (num(0, 12) as usize, num(1, 256), num(2, 4096));
    let list = |i: usize, d: &[f32]| -> Vec<f32> {
        args.get(i).map_or_else(
            || d.to_vec(),
            |s| s.split(',').filter_map(|x| x.parse().ok()).collect(),
        )
    };
    if args.get(3).is_some_and(|s| s == "harmonics") {
        return harmonics(&args);
    }
    if args.get(3).is_some_and(|s| s == "coefficients") {
        return coefficients(&args);
    }
    if args.get(3).is_some_and(|s| s == "ear") {
        return ear(side, spp, ref_spp);
    }
    let thetas = list(3, &[60.0]);
    let phis = list(4, &[180.0]);
    let surface = std::env::var("SURFACE").unwrap_or_else(|_| "smooth".into());
    let preset = std::env::var("PRESET").unwrap_or_else(|_| "light".into());
    let nm: Option<f32> = std::env::var("NM").ok().and_then(|s| s.parse().ok());
    let surface_key = match surface.as_str() {
        "oily" => String::new(),
        s => format!("surface = \"{s}\"\n"),
    };
    let knobs = SkinKnobs {
        azimuth: Azimuth::Harmonics,
        ..SkinKnobs::default()
    };
    let dir = tempfile::tempdir()?;
    let obj = dir.path().join("box.obj");
    // SPHERE=R: an icosphere of radius R mm with its top where the box's is (z = 10 mm).
    let sphere: Option<f32> = std::env::var("SPHERE").ok().and_then(|s| s.parse().ok());
    let (mesh, place) = match sphere {
        Some(r) => (
            render::volumetric::shapes::sphere_obj(6, r),
            format!("translate_mm = [0, 0, {}]\n", 10.0 - r),
        ),
        None => (
            render::volumetric::shapes::box_obj([60.0, 60.0, 20.0]),
            String::new(),
        ),
    };
    std::fs::write(&obj, mesh)?;
    let separable = SkinKnobs {
        azimuth: Azimuth::Separable,
        ..SkinKnobs::default()
    };
    println!(
        "surface,theta_deg,phi_deg,separable_y,separable_se,lobe_y,lobe_se,walk_y,walk_se,separable_error_pct,separable_sigma,lobe_error_pct,lobe_sigma,bssrdf_cpu_s,walk_cpu_s"
    );
    for &theta in &thetas {
        for &phi in &phis {
            let (t, p) = (theta.to_radians(), phi.to_radians());
            let d = 230.0f32;
            let lamp = [
                d * t.sin() * p.cos(),
                d * t.sin() * p.sin(),
                10.0 + d * t.cos(),
            ];
            // CAM_DEG: the camera's angle from the normal (default 45°), its field narrowed
            // with the cosine so that the frame stays on the box.
            let cam = std::env::var("CAM_DEG")
                .ok()
                .and_then(|s| s.parse::<f32>().ok())
                .unwrap_or(45.0)
                .to_radians();
            let fov = 5.0 * cam.cos() / std::f32::consts::FRAC_1_SQRT_2;
            let toml = format!(
                "[camera]\nposition_mm = [{}, 0, {}]\nlook_at_mm = [0, 0, 10]\nfov_deg = {fov}\n\
                 [environment]\nspectrum = \"d65\"\nintensity = 0.005\n\
                 [materials.skin]\ntype = \"skin\"\npreset = \"{preset}\"\n{surface_key}\
                 [[meshes]]\nfile = \"{}\"\nmaterial = \"skin\"\n{place}[[lights]]\ntype = \"sphere\"\n\
                 center_mm = [{}, {}, {}]\nradius_mm = 25\nspectrum = \"blackbody\"\n\
                 temperature_k = 5000\nintensity = 400\n",
                300.0 * cam.sin(),
                10.0 + 300.0 * cam.cos(),
                obj.display(),
                lamp[0],
                lamp[1],
                lamp[2]
            );
            let scene = Scene::from_toml(&toml, "lamp.toml", None, &knobs)?;
            let plain = Scene::from_toml(&toml, "lamp.toml", None, &separable)?;
            if std::env::var("COST").is_ok() {
                // The lobe's cost per sample: the two BSSRDFs rendered in turn, four times each,
                // in this one process (the same load for both).
                let (mut a, mut b) = (0.0, 0.0);
                for _ in 0..4 {
                    a += run(&plain, IntegratorKind::Bssrdf, side, spp, 1, nm)?.2;
                    b += run(&scene, IntegratorKind::Bssrdf, side, spp, 1, nm)?.2;
                }
                println!(
                    "# CPU-s over 4 renders: separable {a:.2}, lobe {b:.2} ({:+.1}%)",
                    100.0 * (b / a - 1.0)
                );
            }
            let s = run(&plain, IntegratorKind::Bssrdf, side, spp, 1, nm)?;
            let b = run(&scene, IntegratorKind::Bssrdf, side, spp, 1, nm)?;
            let w = if ref_spp > 0 {
                run(&scene, IntegratorKind::Volumetric, side, ref_spp, 2, nm)?
            } else {
                (f64::NAN, f64::NAN, 0.0)
            };
            let err = |r: (f64, f64, f64)| {
                let diff = r.0 / w.0 - 1.0;
                (100.0 * diff, diff / (r.1.hypot(w.1) / w.0))
            };
            let (es, ss) = err(s);
            let (eb, sb) = err(b);
            println!(
                "{surface},{theta},{phi},{:.5},{:.5},{:.5},{:.5},{:.5},{:.5},{es:+.2},{ss:+.1},{eb:+.2},{sb:+.1},{:.2},{:.2}",
                s.0, s.1, b.0, b.1, w.0, w.1, b.2, w.2
            );
        }
    }
    Ok(())
}

/// The ear close-up of `thin_slabs ear` (light skin, `SURFACE`, no albedo texture, 9° field on
/// the ear), its pixels split by the centre ray's hit: "thin" (the inward normal meets skin again
/// within 10 mm), "lit" (thick, the back light's centre in view above the surface) and "shade"
/// (the rest); per region the mean of the walk, the separable BSSRDF and the lobe.
fn ear(side: usize, spp: u32, ref_spp: u32) -> anyhow::Result<()> {
    use render::geometry::offset_origin;
    use render::scene::Hit;
    let surface = std::env::var("SURFACE").unwrap_or_else(|_| "smooth".into());
    let toml: String = render::builtin::EAR
        .lines()
        .filter(|l| !l.trim_start().starts_with("albedo_texture"))
        .map(|l| match l.trim() {
            "type = \"skin\"" if surface != "oily" => format!("{l}\nsurface = \"{surface}\""),
            "look_at_mm = [-70, 35, -10]" => "look_at_mm = [-65, 57, 3]".to_string(),
            "fov_deg = 22" => "fov_deg = 9".to_string(),
            _ => l.to_string(),
        })
        .collect::<Vec<_>>()
        .join("\n");
    // LAMP_SCALE=k: the back light's radius × k and its luminance ÷ k² (the same power; the
    // walk's refracted exits find it k² times as often).
    let k: f32 = std::env::var("LAMP_SCALE")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1.0);
    let toml = if k == 1.0 {
        toml
    } else {
        let mut back = false;
        toml.lines()
            .map(|l| {
                if l.starts_with("center_mm = [-110, 60, -220]") {
                    back = true;
                }
                match l.trim() {
                    "radius_mm = 25" if back => format!("radius_mm = {}", 25.0 * k),
                    "intensity = 400" if back => {
                        back = false;
                        format!("intensity = {}", 400.0 / (k * k))
                    }
                    _ => l.to_string(),
                }
            })
            .collect::<Vec<_>>()
            .join("\n")
    };
    let knobs = SkinKnobs {
        azimuth: Azimuth::Harmonics,
        ..SkinKnobs::default()
    };
    let separable = SkinKnobs {
        azimuth: Azimuth::Separable,
        ..SkinKnobs::default()
    };
    let scene = Scene::from_toml(&toml, "ear.toml", None, &knobs)?;
    let plain = Scene::from_toml(&toml, "ear.toml", None, &separable)?;
    let lamp = glam::Vec3::new(-110.0, 60.0, -220.0);
    {
        // Open edges of the skin's mesh (vertices welded by their bits): the walk needs it closed.
        let skin_id = scene
            .materials
            .iter()
            .position(|m| matches!(m, render::material::Material::Skin(_)))
            .unwrap_or(0) as u32;
        let tris = scene.geometry.triangles_of(skin_id);
        let key = |v: glam::Vec3| (v.x.to_bits(), v.y.to_bits(), v.z.to_bits());
        let mut edges = std::collections::HashMap::new();
        for t in &tris {
            for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
                let (ka, kb) = (key(a), key(b));
                let e = if ka < kb { (ka, kb) } else { (kb, ka) };
                *edges.entry(e).or_insert(0u32) += 1;
            }
        }
        let open = edges.values().filter(|&&c| c == 1).count();
        let many = edges.values().filter(|&&c| c > 2).count();
        println!(
            "# skin mesh: {} triangles, {} edges, {open} open, {many} shared by more than two",
            tris.len(),
            edges.len()
        );
    }
    let mut class = Vec::with_capacity(side * side);
    let mut cosines = (0.0f64, 0.0f64, 0.0f64);
    for y in 0..side {
        for x in 0..side {
            let (o, d) = render::testing::pixel_ray(&scene, side, x, y);
            let c = match scene.intersect(o, d, 0.0, f32::INFINITY) {
                Some(Hit::Surface(si))
                    if matches!(
                        scene.materials[si.material as usize],
                        render::material::Material::Skin(_)
                    ) =>
                {
                    let ng = if si.ng.dot(d) > 0.0 { -si.ng } else { si.ng };
                    let thin = scene
                        .geometry
                        .intersect(offset_origin(si.p, ng, -ng), -ng, 0.0, 10.0)
                        .is_some_and(|f| f.material == si.material);
                    let to = lamp - si.p;
                    let dist = to.length();
                    let l = to / dist;
                    let lit = l.dot(ng) > 0.0
                        && !scene
                            .geometry
                            .occluded(offset_origin(si.p, ng, l), l, dist - 30.0);
                    if lit && !thin {
                        let ns = if si.ns.dot(ng) < 0.0 { -si.ns } else { si.ns };
                        cosines.0 += f64::from(l.dot(ng));
                        cosines.1 += f64::from(l.dot(ns).max(0.0));
                        cosines.2 += 1.0;
                    }
                    if thin {
                        0
                    } else if lit {
                        1
                    } else {
                        2
                    }
                }
                _ => 3,
            };
            class.push(c);
        }
    }
    let region = |film: &(Vec<(f64, f64)>, f64), c: usize| {
        let (mut n, mut sum, mut var) = (0.0, 0.0, 0.0);
        for (p, &k) in film.0.iter().zip(&class) {
            if k == c {
                n += 1.0;
                sum += p.0;
                var += p.1;
            }
        }
        (sum / f64::max(n, 1.0), var.sqrt() / f64::max(n, 1.0), n)
    };
    println!(
        "# lit pixels: mean cos to the lamp, face normal {:.4}, shading normal {:.4}",
        cosines.0 / cosines.2,
        cosines.1 / cosines.2
    );
    println!("configuration,spp,region,pixels,mean_y,se,cpu_s");
    let mut films = Vec::new();
    let rows: Vec<(&str, &Scene, IntegratorKind, u32, u64)> = vec![
        ("walk", &scene, IntegratorKind::Volumetric, ref_spp, 2),
        ("separable", &plain, IntegratorKind::Bssrdf, spp, 1),
        ("lobe", &scene, IntegratorKind::Bssrdf, spp, 1),
    ];
    for (label, sc, kind, n, seed) in rows {
        if n == 0 {
            continue;
        }
        let film = pixels(
            sc,
            kind,
            side,
            n,
            seed,
            std::env::var("NM").ok().and_then(|s| s.parse().ok()),
        )?;
        for (c, name) in ["thin", "lit", "shade", "other"].iter().enumerate() {
            let (m, se, px) = region(&film, c);
            println!("{label},{n},{name},{px},{m:.5},{se:.5},{:.2}", film.1);
        }
        films.push(film);
    }
    // DUMP=1: per pixel class, walk and last BSSRDF, as a map of walk / BSSRDF (digits: ratio ×
    // 2, '.' not skin).
    if films.len() == 3 {
        // The walk's tail: per region, the median of walk / BSSRDF over pixels, and both means
        // without the pixels of the walk's brightest tenth.
        for (c, name) in ["thin", "lit", "shade"].iter().enumerate() {
            let mut px: Vec<usize> = (0..class.len()).filter(|&i| class[i] == c).collect();
            if px.is_empty() {
                continue;
            }
            let mut r: Vec<f64> = px
                .iter()
                .map(|&i| films[0].0[i].0 / films[2].0[i].0.max(1e-9))
                .collect();
            r.sort_by(f64::total_cmp);
            px.sort_by(|&a, &b| films[0].0[a].0.total_cmp(&films[0].0[b].0));
            let keep = &px[..px.len() * 9 / 10];
            let mean =
                |k: usize| keep.iter().map(|&i| films[k].0[i].0).sum::<f64>() / keep.len() as f64;
            let top: f64 = px[px.len() * 9 / 10..]
                .iter()
                .map(|&i| films[0].0[i].0)
                .sum::<f64>()
                / px.iter().map(|&i| films[0].0[i].0).sum::<f64>();
            println!(
                "# {name}: median walk/lobe {:.3}; without the walk's brightest 10% of pixels: walk {:.5}, lobe {:.5} ({:+.1}%); that 10% holds {:.0}% of the walk's sum",
                r[r.len() / 2],
                mean(0),
                mean(2),
                100.0 * (mean(2) / mean(0) - 1.0),
                100.0 * top
            );
        }
    }
    if std::env::var("DUMP").is_ok() && films.len() == 3 {
        for y in 0..side {
            let line: String = (0..side)
                .map(|x| {
                    let i = y * side + x;
                    if class[i] == 3 {
                        return '.';
                    }
                    let r = films[0].0[i].0 / films[2].0[i].0.max(1e-9);
                    let d = (r * 2.0).round().clamp(0.0, 9.0) as u32;
                    char::from_digit(d, 10).unwrap_or('?')
                })
                .collect();
            let cls: String = (0..side)
                .map(|x| ['t', 'L', 's', '.'][class[y * side + x]])
                .collect();
            println!("{line}   {cls}");
        }
    }
    Ok(())
}

/// Each pixel's (luminance, variance of its mean) and the process CPU seconds, at the single
/// wavelength `nm` (colour without one).
fn pixels(
    scene: &Scene,
    kind: IntegratorKind,
    side: usize,
    spp: u32,
    seed: u64,
    nm: Option<f32>,
) -> anyhow::Result<(Vec<(f64, f64)>, f64)> {
    let body = BodyIntegrator::build(scene, kind);
    // DEPTH=n: paths of at most n surface hits under the BSSRDF, n + 1 under the walk (whose
    // exit finds the lamp one ray later): DEPTH=1 keeps the light that reaches the camera
    // through one stretch of skin from a light or the sky, and nothing that bounced before.
    let mut path = render::integrator::PathSettings::default();
    if let Some(n) = std::env::var("DEPTH")
        .ok()
        .and_then(|s| s.parse::<u32>().ok())
    {
        path.max_depth = n + u32::from(kind == IntegratorKind::Volumetric);
    }
    let opts = RenderOptions {
        path,
        width: side,
        height: side,
        spp,
        seed,
        noise: None,
        wavelength_nm: nm,
        ..Default::default()
    };
    let t0 = cpu_time::ProcessTime::now();
    let (film, _) = render_with(scene, &body, &opts.validate()?, None)?;
    let cpu = t0.elapsed().as_secs_f64();
    let mut px = Vec::with_capacity(side * side);
    for y in 0..side {
        for x in 0..side {
            px.push((f64::from(film.xyz(x, y)[1]), film.variance(x, y)));
        }
    }
    Ok((px, cpu))
}

/// (mean luminance over the frame, its standard error, process CPU seconds).
fn run(
    scene: &Scene,
    kind: IntegratorKind,
    side: usize,
    spp: u32,
    seed: u64,
    nm: Option<f32>,
) -> anyhow::Result<(f64, f64, f64)> {
    let (px, cpu) = pixels(scene, kind, side, spp, seed, nm)?;
    let n = px.len() as f64;
    let (sum, var) = px.iter().fold((0.0, 0.0), |(s, v), p| (s + p.0, v + p.1));
    Ok((sum / n, var.sqrt() / n, cpu))
}

/// `harmonics NM MU_I PHOTONS MAX_COLLISIONS`: the Monte Carlo's azimuthal harmonics of light
/// skin at one wavelength and incidence against the separable form's value (smooth surface).
fn harmonics(args: &[String]) -> anyhow::Result<()> {
    use multipole::exact::montecarlo::{ObliqueOptions, azimuthal_harmonics};
    let f = |i: usize, d: f64| args.get(i).and_then(|s| s.parse().ok()).unwrap_or(d);
    let (nm, mu_i, photons, cap) = (f(4, 550.0), f(5, 0.5), f(6, 1e5) as u64, f(7, 64.0) as u32);
    let preset = std::env::var("PRESET").unwrap_or_else(|_| "light".into());
    let toml = format!(
        "[camera]\nposition_mm = [0, 0, 300]\nlook_at_mm = [0, 0, 0]\nfov_deg = 10\n\
         [materials.skin]\ntype = \"skin\"\npreset = \"{preset}\"\nsurface = \"smooth\"\n\
         [[meshes]]\nshape = \"quad\"\nmaterial = \"skin\"\n"
    );
    let scene = Scene::from_toml(&toml, "h.toml", None, &SkinKnobs::default())?;
    let render::material::Material::Skin(skin) = &scene.materials[0] else {
        anyhow::bail!("no skin");
    };
    let ss = skin.subsurface.as_ref().expect("BSSRDF");
    let medium = skin
        .media
        .every_10nm()
        .find(|(l, _)| (l - nm).abs() < 1e-6)
        .map(|(_, m)| m.clone())
        .expect("a 10-nm row");
    let opts = ObliqueOptions::new(photons, cap, 4, 8, 7)?;
    let t0 = cpu_time::ProcessTime::now();
    let h = azimuthal_harmonics(&medium, mu_i, &opts)?;
    let cpu = t0.elapsed().as_secs_f64();
    let d = &ss.directional;
    let nmf = nm as f32;
    let a_i = d.incidence().map_or(1.0, |g| g.gain(mu_i as f32, nmf));
    let r_tot = ss.table.total(nmf);
    println!(
        "escaped {:.4} (R_tot {r_tot:.4}), {cpu:.2} CPU-s",
        h.escaped
    );
    println!("mu_o,F0/fsep,c1,c2,c3,c4,se_c1,M(0),M(90),M(180)");
    for k in 0..opts.bins() {
        let mu_o = opts.bin_mu(k) as f32;
        let fsep = f64::from(
            a_i * r_tot * d.factor(mu_o, nmf) / (d.normalisation_at(nmf) * std::f32::consts::PI),
        );
        let c: Vec<f64> = (0..=4).map(|m| h.f[m][k] / fsep).collect();
        let m_at =
            |phi: f64| 1.0 + 2.0 * (1..=4).map(|m| c[m] * (m as f64 * phi).cos()).sum::<f64>();
        println!(
            "{mu_o:.3},{:.4},{:+.4},{:+.4},{:+.4},{:+.4},{:.4},{:.4},{:.4},{:.4}",
            c[0],
            c[1],
            c[2],
            c[3],
            c[4],
            h.se[1][k] / fsep,
            m_at(0.0),
            m_at(std::f64::consts::FRAC_PI_2),
            m_at(std::f64::consts::PI)
        );
    }
    Ok(())
}

/// `coefficients PHOTONS MAX_COLLISIONS [PRESET]`: the lobe's fitted A₁, A₂ per row for those
/// Monte Carlo settings (smooth surface), and the CPU seconds of the fit.
fn coefficients(args: &[String]) -> anyhow::Result<()> {
    use render::bssrdf::azimuth::AZIMUTH_ROWS_NM;
    use render::bssrdf::{AzimuthOptions, AzimuthalLobe, Directional, EnergySplit};
    let f = |i: usize, d: f64| args.get(i).and_then(|s| s.parse().ok()).unwrap_or(d);
    let (photons, cap) = (f(4, 2e4) as u64, f(5, 128.0) as u32);
    let preset = args.get(6).map_or("light", String::as_str);
    let toml = format!(
        "[camera]\nposition_mm = [0, 0, 300]\nlook_at_mm = [0, 0, 0]\nfov_deg = 10\n\
         [materials.skin]\ntype = \"skin\"\npreset = \"{preset}\"\nsurface = \"smooth\"\n\
         [[meshes]]\nshape = \"quad\"\nmaterial = \"skin\"\n"
    );
    let knobs = SkinKnobs {
        azimuth: Azimuth::Separable,
        ..SkinKnobs::default()
    };
    let scene = Scene::from_toml(&toml, "c.toml", None, &knobs)?;
    let render::material::Material::Skin(skin) = &scene.materials[0] else {
        anyhow::bail!("no skin");
    };
    let ss = skin.subsurface.as_ref().expect("BSSRDF");
    let fresnel = Directional::new(skin.surface.clone(), EnergySplit::Fresnel);
    let fresnel = match ss.directional.incidence_arc() {
        Some(g) => fresnel.with_incidence(g),
        None => fresnel,
    };
    let rows: Vec<(f64, &multipole::LayeredMedium)> = skin.media.every_10nm().collect();
    let t0 = cpu_time::ProcessTime::now();
    let lobe = AzimuthalLobe::build(
        |nm| {
            rows.iter()
                .find(|r| (r.0 - nm).abs() < 1e-6)
                .expect("row")
                .1
        },
        &fresnel,
        |nm| ss.table.total(nm),
        AzimuthOptions {
            photons,
            max_collisions: cap,
        },
    )?;
    let cpu = t0.elapsed().as_secs_f64();
    println!("preset,photons,max_collisions,nm,a1,cpu_s");
    for nm in AZIMUTH_ROWS_NM {
        let a1 = lobe.coefficient(nm as f32);
        println!("{preset},{photons},{cap},{nm},{a1:.4},{cpu:.2}");
    }
    Ok(())
}
