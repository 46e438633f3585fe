//! Heterogeneous skin (docs/physics.md §19): chromophore maps against the scalar skin, the BSSRDF
//! against the volumetric walk on a split slab and a freckle, the reciprocity of the default
//! profile rule, the profile grid's interpolation error, and the map keys' errors.

use render::error::RenderError;
use render::fidelity::FidelityKnobs;
use render::fidelity::grid::{GridSettings, interpolation_error, profile_grid};
use render::integrator::IntegratorKind;
use render::material::SkinKnobs;
use render::scene::Scene;
use render::testing::hetero::{
    exr_bytes, load_error, melanin_exr, region, slab_obj, strip_columns, strip_scene,
};
use skin_optics::{Preset, SkinParams};

const NM: f32 = 650.0;

/// A scalar skin of C_m 0.3 and a skin of scalar C_m 0.02 whose uniform melanin map holds 0.3
/// render alike at 650 nm, with the BSSRDF and with the volumetric walk, within 3σ of the render
/// noise (one seed: the walk's σa comes from the corners, equal to the scalar's to f32 rounding,
/// and the BSSRDF's one-node grid differs from the scalar table only in its wavelength rows, so
/// the renders share nearly every path). The map is read: without it the pixels are over five
/// times brighter.
#[test]
fn uniform_map_renders_as_the_scalar_skin() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("maps.exr"), melanin_exr(8, 1, |_, _| 0.3)).unwrap();
    let scalar = strip_scene(dir.path(), 1.0, 4, "melanin = 0.3");
    let mapped = strip_scene(dir.path(), 1.0, 4, "melanin = 0.02\nmaps = \"maps.exr\"");
    let light = strip_scene(dir.path(), 1.0, 4, "melanin = 0.02");
    for (kind, spp) in [
        (IntegratorKind::Bssrdf, 256),
        (IntegratorKind::Volumetric, 256),
    ] {
        let mean = |s: &Scene| region(&strip_columns(s, kind, 4, NM, spp, 5), 1.0, -1.0, 1.0);
        let ((va, sa), (vb, sb), (vl, _)) = (mean(&scalar), mean(&mapped), mean(&light));
        assert!(
            (va - vb).abs() <= 3.0 * sa.hypot(sb),
            "{kind:?}: scalar {va} ± {sa} vs map {vb} ± {sb}"
        );
        assert!(
            vl > 5.0 * vb,
            "{kind:?}: the map is read: light {vl} vs mapped {vb}"
        );
    }
}

/// The BSSRDF with the default rule against the volumetric walk at 650 nm on the slab split at
/// x = 0 (C_m 0.3 left, 0.02 right) and on a 1-mm freckle of C_m 0.15: region means ≥ 1 mm from
/// the boundaries within 8% + 3σ (the uniform slabs' own BSSRDF–walk gap at this wavelength is
/// 3.7–5.9%, and heterogeneity adds at most 2% to it, BENCHMARKS.md "Heterogeneous skin"); at the
/// freckle's centre within 12% + 3σ (5.7% measured at high counts); and the geometric rule's
/// transition nearer the walk than half the entry rule's (RMS 8% against 55–90% measured).
#[test]
fn split_slab_and_freckle_follow_the_volumetric_walk() {
    let dir = tempfile::tempdir().unwrap();
    let half = 4.0;
    let cols = 16;
    type Regions = &'static [(f32, f32, f64)];
    let cases: [(&str, Vec<u8>, Regions); 2] = [
        (
            "split",
            melanin_exr(256, 1, |x, _| if x < 0.0 { 0.3 } else { 0.02 }),
            &[(-4.0, -1.0, 0.08), (1.0, 4.0, 0.08)],
        ),
        (
            "freckle",
            melanin_exr(
                256,
                256,
                |x, y| if x * x + y * y <= 0.25 { 0.15 } else { 0.02 },
            ),
            &[(-4.0, -1.5, 0.08), (-0.3, 0.3, 0.12), (1.5, 4.0, 0.08)],
        ),
    ];
    for (name, map, regions) in cases {
        std::fs::write(dir.path().join("maps.exr"), map).unwrap();
        let keys = |rule: &str| format!("maps = \"maps.exr\"\nprofile_blend = \"{rule}\"");
        let scene = strip_scene(dir.path(), half, cols, &keys("geometric"));
        let vol = strip_columns(&scene, IntegratorKind::Volumetric, cols, NM, 256, 7);
        let geo = strip_columns(&scene, IntegratorKind::Bssrdf, cols, NM, 256, 8);
        for &(from, to, allowance) in regions {
            let (v, vs) = region(&vol, half, from, to);
            let (b, bs) = region(&geo, half, from, to);
            assert!(
                (b - v).abs() <= allowance * v + 3.0 * vs.hypot(bs),
                "{name} [{from}, {to}] mm: BSSRDF {b} ± {bs} vs walk {v} ± {vs}"
            );
        }
        let entry_scene = strip_scene(dir.path(), half, cols, &keys("entry"));
        let entry = strip_columns(&entry_scene, IntegratorKind::Bssrdf, cols, NM, 256, 8);
        let rms = |c: &[(f64, f64)]| {
            let near: Vec<f64> = (0..cols)
                .filter(|&i| {
                    let x = -half + (i as f32 + 0.5) * 2.0 * half / cols as f32;
                    x.abs() < 1.0
                })
                .map(|i| (c[i].0 / vol[i].0 - 1.0).powi(2))
                .collect();
            (near.iter().sum::<f64>() / near.len() as f64).sqrt()
        };
        let (g, e) = (rms(&geo), rms(&entry));
        assert!(
            g < 0.5 * e,
            "{name}: transition RMS geometric {g} vs entry {e}"
        );
    }
}

/// One pixel looking straight down at B lit by a narrow spot light shining straight down on A, and
/// the same with A and B swapped, A and B 2 mm either side of the split, the spot's disc and the
/// pixel's footprint alike (1 mm radius, each within uniform skin) and 4 mm apart (so no light
/// falls on the viewed point itself): with the geometric rule the two pixels agree within 3σ of
/// their noise (the rule is symmetric in the two ends; one seed in mirrored scenes draws mirrored
/// samples, so an asymmetric rule shows far outside that band); with the exit rule they differ
/// by more than 6σ (the dark end's profile against the light end's: 700× here).
#[test]
fn the_geometric_rule_is_reciprocal_on_the_split_slab() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("slab.obj"), slab_obj()).unwrap();
    std::fs::write(
        dir.path().join("maps.exr"),
        melanin_exr(256, 1, |x, _| if x < 0.0 { 0.3 } else { 0.02 }),
    )
    .unwrap();
    let top = 10.0;
    let pixel = |camera_x: f32, light_x: f32, rule: &str| {
        let text = format!(
            "[camera]\nposition_mm = [{camera_x}, 0, 400]\nlook_at_mm = [{camera_x}, 0, {top}]\nfov_deg = 0.3\n\
             [materials.skin]\ntype = \"skin\"\nmaps = \"maps.exr\"\nprofile_blend = \"{rule}\"\n\
             [[meshes]]\nfile = \"slab.obj\"\nmaterial = \"skin\"\n\
             [[lights]]\ntype = \"spot\"\nposition_mm = [{light_x}, 0, 400]\nlook_at_mm = [{light_x}, 0, {top}]\n\
             inner_deg = 0.15\nouter_deg = 0.15\nintensity = 1e6\n"
        );
        let scene =
            Scene::from_toml(&text, "pair.toml", Some(dir.path()), &SkinKnobs::default()).unwrap();
        strip_columns(&scene, IntegratorKind::Bssrdf, 1, NM, 40_000, 9)[0]
    };
    let (a, b) = (-2.0, 2.0);
    let (ab, sab) = pixel(b, a, "geometric");
    let (ba, sba) = pixel(a, b, "geometric");
    assert!(
        ab > 4.0 * sab && ba > 4.0 * sba,
        "light arrives: {ab} ± {sab}, {ba} ± {sba}"
    );
    assert!(
        (ab - ba).abs() <= 3.0 * sab.hypot(sba),
        "geometric: {ab} ± {sab} vs swapped {ba} ± {sba}"
    );
    let (eab, seab) = pixel(b, a, "exit");
    let (eba, seba) = pixel(a, b, "exit");
    assert!(
        (eab - eba).abs() > 6.0 * seab.hypot(seba),
        "exit: {eab} ± {seab} vs swapped {eba} ± {seba}"
    );
}

/// The grid over C_m ∈ [0.02, 0.3] (β_m 0.5, C_h 0.01; 9 nodes) meets its 2% error target at the
/// cells' centres, and at random parameters inside the box its error against directly built
/// tables stays within 1.25 × the measured bound (linear interpolation errs most near a cell's
/// centre; the margin covers the curvature's change across a cell); the coarsest grid (two nodes
/// per axis) errs more than the target, so the measure decides the resolution.
#[test]
fn profile_grid_error_stays_within_its_measured_bound() {
    let params = SkinParams::preset(Preset::Light);
    // One wavelength step for every table, as a skin with maps builds its grid.
    let fidelity = FidelityKnobs {
        wavelength_step_nm: Some(10.0),
        ..FidelityKnobs::default()
    };
    let settings = |target: f32| GridSettings {
        params: &params,
        phase_g: multipole::DEFAULT_G,
        surface: multipole::Surface::Fresnel,
        method: multipole::Method::default(),
        shape_escapes: None,
        fidelity: &fidelity,
        target,
    };
    let range = [[0.02, 0.3], [0.5, 0.5], [0.01, 0.01]];
    let coarse = profile_grid(&settings(f32::MAX), range).unwrap();
    assert_eq!(coarse.axes()[0].len(), 2);
    let grid = profile_grid(&settings(0.02), range).unwrap();
    assert!(coarse.max_error > 0.02, "coarse {}", coarse.max_error);
    assert!(grid.max_error <= 0.02, "refined {}", grid.max_error);
    assert_eq!(grid.axes()[1], vec![0.5]);
    let mut state = 0x2545_f491u32;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        f64::from(state) / f64::from(u32::MAX)
    };
    for _ in 0..8 {
        let p = [(0.02 + 0.28 * next()) as f32, 0.5, 0.01];
        let q = params
            .with_melanin(f64::from(p[0]))
            .unwrap()
            .with_hemoglobin(f64::from(p[2]))
            .unwrap();
        let media = render::media::SkinMedia::new(&q, multipole::DEFAULT_G).unwrap();
        let (direct, _) = render::fidelity::tables::skin_table(
            &q,
            &media,
            multipole::Method::default(),
            None,
            &fidelity,
        )
        .unwrap();
        let e = interpolation_error(&grid.corners(p), &direct);
        assert!(
            e <= 1.25 * grid.max_error,
            "{p:?}: {e} against the bound {}",
            grid.max_error
        );
    }
}

/// Each bad map is a typed error naming its key and file: a missing file, maps of different
/// sizes, a NaN texel, and a value outside [0, 1] after the edits (nothing is clamped); a grey
/// 16-bit PNG holds its values directly.
#[test]
fn bad_maps_are_errors_naming_key_and_file() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (e, m) = load_error(d, "melanin_map = \"absent.exr\"");
    assert!(matches!(e, RenderError::ChromophoreMap { .. }), "{m}");
    assert!(
        m.contains("materials.skin.melanin_map") && m.contains("absent.exr"),
        "{m}"
    );

    std::fs::write(
        d.join("m.exr"),
        exr_bytes(4, 2, vec![("melanin", vec![0.1; 8])]),
    )
    .unwrap();
    std::fs::write(
        d.join("h.exr"),
        exr_bytes(2, 2, vec![("hemoglobin", vec![0.01; 4])]),
    )
    .unwrap();
    let (_, m) = load_error(d, "melanin_map = \"m.exr\"\nhemoglobin_map = \"h.exr\"");
    assert!(
        m.contains("materials.skin.hemoglobin_map") && m.contains("2×2") && m.contains("4×2"),
        "{m}"
    );

    let mut nan = vec![0.1; 8];
    nan[5] = f32::NAN;
    std::fs::write(d.join("n.exr"), exr_bytes(4, 2, vec![("melanin", nan)])).unwrap();
    let (_, m) = load_error(d, "maps = \"n.exr\"");
    assert!(
        m.contains("materials.skin.maps")
            && m.contains("texel (1, 1)")
            && m.contains("not a number"),
        "{m}"
    );

    let (e, m) = load_error(
        d,
        "melanin_map = \"m.exr\"\nmelanin_scale = 4\nmelanin_offset = 0.7",
    );
    assert!(matches!(e, RenderError::ChromophoreMap { .. }), "{m}");
    assert!(
        m.contains("materials.skin.melanin_map") && m.contains("1.1") && m.contains("[0, 1]"),
        "{m}"
    );

    let png = image::ImageBuffer::<image::Luma<u16>, _>::from_raw(2, 1, vec![0u16, 65535]).unwrap();
    png.save(d.join("g.png")).unwrap();
    std::fs::write(
        d.join("m2.exr"),
        exr_bytes(2, 1, vec![("melanin", vec![0.1; 2])]),
    )
    .unwrap();
    let (_, m) = load_error(
        d,
        "melanin_map = \"m2.exr\"\nhemoglobin_map = \"g.png\"\nhemoglobin_offset = 0.01",
    );
    assert!(m.contains("hemoglobin") && m.contains("1.01"), "{m}");
}

/// `fit_maps` fits the maps to the albedo texture at load, as `skin maps` does: a 2 × 1 PNG of
/// two skins of the exact model (C_m 0.02 and 0.2, β_m 0.6, C_h 0.02 and 0.05; 8-bit sRGB)
/// gives each texel back its C_m within 10 %, and the lighter one its C_h within 20 %: 8-bit sRGB
/// cannot tell C_h 0.02 from 0.0175 there (both encode as #9c7f6e, 0.38 ΔE2000 apart), nor C_h
/// 0.05 from 0.01 in the darker skin (#362920 against #362a20), whose C_h is not checked. Without
/// an albedo texture, beside `maps`, or with a bad exposure the key is named.
#[test]
fn fit_maps_fits_the_albedo_texture() {
    use skin_fit::ColourModel;
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let model = ColourModel::new(
        10.0,
        multipole::Method::Exact,
        skin_fit::FitOptions::default().base,
    )
    .unwrap();
    let truth = [[0.02, 0.6, 0.02], [0.2, 0.6, 0.05]];
    let rgb: Vec<u8> = truth
        .iter()
        .flat_map(|p| {
            let skin = model.skin(p[0], p[1], p[2]).unwrap();
            let linear = model.xyz(&skin).unwrap().to_linear_srgb().0;
            linear.map(|c| (skin_optics::color::srgb_encode(c) * 255.0).round() as u8)
        })
        .collect();
    image::RgbImage::from_raw(2, 1, rgb)
        .unwrap()
        .save(d.join("albedo.png"))
        .unwrap();
    let scene = strip_scene(
        d,
        1.0,
        4,
        "albedo_texture = \"albedo.png\"\nfit_maps = \"1\"",
    );
    let render::material::Material::Skin(skin) = &scene.materials[0] else {
        panic!("skin");
    };
    let maps = &skin.maps.as_ref().expect("fitted maps").maps;
    for (k, p) in truth.iter().enumerate() {
        let uv = glam::Vec2::new(0.25 + 0.5 * k as f32, 0.5);
        let [c_m, _, c_h] = maps.at(uv).map(f64::from);
        assert!((c_m / p[0] - 1.0).abs() < 0.1, "texel {k}: C_m {c_m}");
        assert!(
            k == 1 || (c_h / p[2] - 1.0).abs() < 0.2,
            "texel {k}: C_h {c_h}"
        );
    }
    std::fs::write(d.join("maps.exr"), melanin_exr(2, 1, |_, _| 0.1)).unwrap();
    for (keys, want) in [
        ("fit_maps = \"1\"", "needs an albedo_texture"),
        (
            "albedo_texture = \"albedo.png\"\nfit_maps = \"1\"\nmaps = \"maps.exr\"",
            "not both",
        ),
        (
            "albedo_texture = \"albedo.png\"\nfit_maps = \"bright\"",
            "[0.125, 2]",
        ),
    ] {
        let (_, m) = load_error(d, keys);
        assert!(
            m.contains("materials.skin.fit_maps") && m.contains(want),
            "{m}"
        );
    }
}

/// `melanin_ita_deg` shifts every texel's melanin by the one offset that gives the maps' typical
/// skin (each parameter's median over the texels) that ITA°: on a map of C_m 0.01–0.04 asked for
/// −34°, the material's skin reads −34° in the exact model's colour within 0.01° (its C_m is
/// stored in f32), and its C_m is the median texel's plus the offset, so the offset moved it
/// (the unshifted median, 0.03, reads far lighter). The key's errors name it: beside
/// `melanin_offset`, outside [−90, 90], beyond what leaves every texel in [0, 1], without a map.
#[test]
fn melanin_ita_deg_gives_the_typical_skin_that_ita() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(
        d.join("m.exr"),
        exr_bytes(4, 1, vec![("melanin", vec![0.01, 0.04, 0.02, 0.03])]),
    )
    .unwrap();
    let scene = strip_scene(d, 1.0, 4, "melanin_map = \"m.exr\"\nmelanin_ita_deg = -34");
    let render::material::Material::Skin(skin) = &scene.materials[0] else {
        panic!("a skin");
    };
    let model = skin_fit::ColourModel::new(10.0, multipole::Method::Exact, skin.params).unwrap();
    let ita = |p: &SkinParams| model.lab(p).unwrap().ita_deg();
    assert!(
        (ita(&skin.params) + 34.0).abs() < 0.01,
        "{}",
        ita(&skin.params)
    );
    let unshifted = skin.params.with_melanin(0.03).unwrap();
    assert!(ita(&unshifted) > 0.0, "{}", ita(&unshifted));
    for (keys, want) in [
        (
            "melanin_map = \"m.exr\"\nmelanin_offset = 0.1\nmelanin_ita_deg = 0",
            "not both",
        ),
        (
            "melanin_map = \"m.exr\"\nmelanin_ita_deg = 95",
            "outside [-90, 90]",
        ),
        (
            "melanin_map = \"m.exr\"\nmelanin_ita_deg = 89",
            "reaches with every texel",
        ),
        ("melanin_ita_deg = 0", "need a map"),
    ] {
        let (_, m) = load_error(d, keys);
        assert!(
            m.contains("materials.skin") && m.contains("melanin_ita_deg") && m.contains(want),
            "{keys}: {m}"
        );
    }
}

/// On a 240-mm sheet of C_m 0.3 skin (60 × 60 quads) with a 2-mm disc of C_m 0.02, the wider
/// profile each triangle mixes into its radii (`NearbyWidest`) is the light skin's wherever a
/// point of the triangle lies within the probes' reach R of the disc (the last tabulated radius of
/// the grid's widest profile), so its weights stay bounded there; and the dark skin's own node
/// beyond 3R plus the cells' edge, where no probe can reach light skin: the bound is local.
#[test]
fn the_widest_within_reach_covers_the_light_skin_it_can_reach_and_no_farther() {
    use render::integrator::widest::NearbyWidest;
    use render::material::Material;
    let dir = tempfile::tempdir().unwrap();
    let (side, n) = (240.0f32, 60usize);
    let mut obj = String::new();
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (
                -0.5 * side + side * i as f32 / n as f32,
                -0.5 * side + side * j as f32 / n as f32,
            );
            obj += &format!(
                "v {x} {y} 0\nvt {} {}\n",
                (x + 0.5 * side) / side,
                (0.5 * side - y) / side
            );
        }
    }
    obj += "vn 0 0 1\n";
    for j in 0..n {
        for i in 0..n {
            let v = |a: usize, b: usize| 1 + a + (n + 1) * b;
            let (p, q, r, s) = (v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1));
            obj += &format!("f {p}/{p}/1 {q}/{q}/1 {r}/{r}/1\nf {p}/{p}/1 {r}/{r}/1 {s}/{s}/1\n");
        }
    }
    std::fs::write(dir.path().join("sheet.obj"), obj).unwrap();
    let (texels, disc) = (480usize, glam::Vec2::new(40.0, 0.0));
    let values = (0..texels * texels)
        .map(|k| {
            let (i, j) = (k % texels, k / texels);
            let x = -0.5 * side + (i as f32 + 0.5) * side / texels as f32;
            let y = 0.5 * side - (j as f32 + 0.5) * side / texels as f32;
            if glam::Vec2::new(x, y).distance(disc) <= 2.0 {
                0.02
            } else {
                0.3
            }
        })
        .collect();
    std::fs::write(
        dir.path().join("maps.exr"),
        exr_bytes(texels, texels, vec![("melanin", values)]),
    )
    .unwrap();
    let text = "[camera]\nposition_mm = [0, 0, 400]\nlook_at_mm = [0, 0, 0]\nfov_deg = 10\n\
                [materials.skin]\ntype = \"skin\"\nmaps = \"maps.exr\"\n\
                [[meshes]]\nfile = \"sheet.obj\"\nmaterial = \"skin\"\n";
    let scene =
        Scene::from_toml(text, "sheet.toml", Some(dir.path()), &SkinKnobs::default()).unwrap();
    let Material::Skin(skin) = &scene.materials[0] else {
        panic!("skin expected")
    };
    let maps = skin.maps.as_ref().unwrap();
    let reach = skin
        .subsurface
        .as_ref()
        .unwrap()
        .table
        .largest_radius_for_energy_mm(1.0);
    let light = maps.grid.low_corner([0.02, 0.5, 0.0]).unwrap();
    let dark = maps.grid.low_corner([0.3, 0.5, 0.0]).unwrap();
    assert_ne!(light, dark);
    let widest = NearbyWidest::build(&scene);
    let (mut near, mut far) = (0, 0);
    for t in 0..scene.geometry.triangle_count() as u32 {
        let p = scene.geometry.triangle(t);
        let distance = |q: glam::Vec3| q.truncate().distance(disc) - 2.0;
        let nearest = p.iter().map(|&q| distance(q)).fold(f32::INFINITY, f32::min);
        let node = widest.node(t).expect("a node per triangle");
        if nearest < reach - 0.5 * side / n as f32 {
            near += 1;
            assert_eq!(
                node, light,
                "triangle {t}, {nearest} mm from the disc (R {reach} mm)"
            );
        } else if nearest > 3.0 * reach + 2.0 * side / n as f32 {
            far += 1;
            assert_eq!(
                node, dark,
                "triangle {t}, {nearest} mm from the disc (R {reach} mm)"
            );
        }
    }
    assert!(near > 4 && far > 1000, "{near} near, {far} far");
}
