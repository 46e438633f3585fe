//! Per-texel epidermis thickness (docs/physics.md §19): maps whose `thin_epidermis` channel flags
//! texels render them as the skin with the thin epidermis, with the BSSRDF and the volumetric walk,
//! and the channel's errors.

use render::error::RenderError;
use render::integrator::IntegratorKind;
use render::material::{Material, SkinKnobs, SkinMaterial};
use render::scene::Scene;
use render::testing::hetero::{SLAB_SIDE_MM, load_error, region, strip_columns, strip_scene};
use render::texture::channels_exr_bytes_with;

/// 550 nm: melanin and blood both absorb, so the epidermis' thickness shows.
const NM: f32 = 550.0;

/// C_m of the test skin: the epidermis' σa at 550 nm is then about 6 mm⁻¹, so its filter
/// exp(−2 σa d) differs between d = 0.25 and 0.05 mm by a factor of about ten.
const MELANIN: f32 = 0.1;

/// A maps.exr over the slab's face, `side_x` × 1 texels: C_m [`MELANIN`] everywhere and the
/// `thin_epidermis` flag `flag(x)` at each texel's centre x (mm), with the attribute
/// `thin_epidermis_mm` = `mm` when given.
fn thin_exr(side_x: usize, flag: impl Fn(f32) -> f32, mm: Option<f32>) -> Vec<u8> {
    let h = 0.5 * SLAB_SIDE_MM;
    let flags = (0..side_x)
        .map(|i| flag(-h + (i as f32 + 0.5) * SLAB_SIDE_MM / side_x as f32))
        .collect();
    let attributes: Vec<(&str, f32)> = mm.map(|v| ("thin_epidermis_mm", v)).into_iter().collect();
    channels_exr_bytes_with(
        side_x,
        1,
        vec![
            ("melanin", vec![MELANIN; side_x]),
            ("thin_epidermis", flags),
        ],
        &attributes,
    )
    .unwrap()
}

/// `scene` with its skin replaced by the same scalar skin under an epidermis `d_mm` thick (the
/// scene file has no thickness key).
fn with_epidermis(mut scene: Scene, d_mm: f64) -> Scene {
    let Material::Skin(skin) = &scene.materials[0] else {
        panic!("skin");
    };
    let params = skin.params.with_epidermis_thickness_mm(d_mm).unwrap();
    scene.materials[0] = Material::Skin(
        SkinMaterial::build(params, brdf::DEFAULT_ROUGHNESS, None, &SkinKnobs::default()).unwrap(),
    );
    scene
}

/// A uniform map flagging every texel thin (0.05 mm) renders as the scalar skin whose epidermis
/// is 0.05 mm thick, with the BSSRDF and with the volumetric walk, within 3σ of the two renders'
/// noise plus 2% (the BSSRDF's thin grid holds that skin's table on the material's wavelength
/// rows, the scalar skin its own). The flag
/// is read: with `thin_epidermis = false` the same maps render under the 0.25 mm epidermis, less
/// than half as bright (the walk at high counts: 0.069 against 0.201, BENCHMARKS.md
/// "Heterogeneous skin").
#[test]
fn uniform_thin_map_renders_as_the_scalar_thin_skin() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("maps.exr"),
        thin_exr(8, |_| 1.0, Some(0.05)),
    )
    .unwrap();
    let scalar = with_epidermis(
        strip_scene(dir.path(), 1.0, 4, &format!("melanin = {MELANIN}")),
        0.05,
    );
    let mapped = strip_scene(dir.path(), 1.0, 4, "maps = \"maps.exr\"");
    let thick = strip_scene(
        dir.path(),
        1.0,
        4,
        "maps = \"maps.exr\"\nthin_epidermis = false",
    );
    for (kind, spp) in [
        (IntegratorKind::Bssrdf, 256),
        (IntegratorKind::Volumetric, 256),
    ] {
        let mean = |s: &Scene| region(&strip_columns(s, kind, 4, NM, spp, 5), 1.0, -1.0, 1.0);
        let ((va, sa), (vb, sb), (vt, _)) = (mean(&scalar), mean(&mapped), mean(&thick));
        assert!(
            (va - vb).abs() <= 0.02 * va + 3.0 * sa.hypot(sb),
            "{kind:?}: scalar 0.05 mm {va} ± {sa} vs thin map {vb} ± {sb}"
        );
        assert!(
            vt < 0.5 * vb,
            "{kind:?}: the flag is read: 0.25 mm {vt} vs thin {vb}"
        );
    }
}

/// The slab split at x = 0 into thin (0.05 mm, left) and normal (0.25 mm, right) epidermis over
/// the same chromophores, at 550 nm: the BSSRDF with the default rule against the volumetric walk,
/// region means ≥ 1 mm from the split within 3% + 3σ (the uniform slabs' own BSSRDF–walk gap,
/// measured at 550 nm with high counts, is 1.3% thin and 1.2% normal, and the split changes it by
/// at most 0.7%; BENCHMARKS.md "Heterogeneous skin"), and the two halves at least twice apart in
/// both (0.20 against 0.069 measured: the flag's effect is what is tested).
#[test]
fn split_thin_slab_follows_the_volumetric_walk() {
    let dir = tempfile::tempdir().unwrap();
    let (half, cols) = (4.0, 16);
    std::fs::write(
        dir.path().join("maps.exr"),
        thin_exr(256, |x| if x < 0.0 { 1.0 } else { 0.0 }, Some(0.05)),
    )
    .unwrap();
    let scene = strip_scene(dir.path(), half, cols, "maps = \"maps.exr\"");
    let vol = strip_columns(&scene, IntegratorKind::Volumetric, cols, NM, 256, 7);
    let bss = strip_columns(&scene, IntegratorKind::Bssrdf, cols, NM, 256, 8);
    let mut means = Vec::new();
    for (from, to) in [(-4.0, -1.0), (1.0, 4.0)] {
        let (v, vs) = region(&vol, half, from, to);
        let (b, bs) = region(&bss, half, from, to);
        assert!(
            (b - v).abs() <= 0.03 * v + 3.0 * vs.hypot(bs),
            "[{from}, {to}] mm: BSSRDF {b} ± {bs} vs walk {v} ± {vs}"
        );
        means.push((v, b));
    }
    let ((thin_v, thin_b), (thick_v, thick_b)) = (means[0], means[1]);
    assert!(
        thin_v > 2.0 * thick_v && thin_b > 2.0 * thick_b,
        "thin {thin_v} / {thin_b} vs normal {thick_v} / {thick_b}"
    );
}

/// A flag outside [0, 1], a file without the thickness attribute (as written before it was
/// recorded) or with a thickness outside (0, 10] mm, and a bad `thin_epidermis_mm` key are each a
/// one-line typed error naming the key and the file; the key supplies a missing attribute.
#[test]
fn bad_thin_epidermis_is_an_error_naming_key_and_file() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("two.exr"), thin_exr(4, |_| 2.0, Some(0.05))).unwrap();
    let (e, m) = load_error(d, "maps = \"two.exr\"");
    assert!(matches!(e, RenderError::ChromophoreMap { .. }), "{m}");
    assert!(
        m.contains("materials.skin.maps")
            && m.contains("two.exr")
            && m.contains("thin_epidermis")
            && m.contains("[0, 1]")
            && !m.contains('\n'),
        "{m}"
    );
    std::fs::write(d.join("old.exr"), thin_exr(4, |_| 1.0, None)).unwrap();
    let (e, m) = load_error(d, "maps = \"old.exr\"");
    assert!(matches!(e, RenderError::ChromophoreMap { .. }), "{m}");
    assert!(
        m.contains("materials.skin.maps")
            && m.contains("old.exr")
            && m.contains("thin_epidermis_mm")
            && !m.contains('\n'),
        "{m}"
    );
    std::fs::write(d.join("deep.exr"), thin_exr(4, |_| 1.0, Some(20.0))).unwrap();
    let (_, m) = load_error(d, "maps = \"deep.exr\"");
    assert!(
        m.contains("materials.skin.maps") && m.contains("deep.exr") && m.contains("(0, 10] mm"),
        "{m}"
    );
    let (_, m) = load_error(d, "maps = \"old.exr\"\nthin_epidermis_mm = 0");
    assert!(
        m.contains("materials.skin.thin_epidermis_mm") && m.contains("(0, 10] mm"),
        "{m}"
    );
    let (_, m) = load_error(d, "thin_epidermis_mm = 0.05");
    assert!(m.contains("need a map"), "{m}");
    let scene = strip_scene(d, 1.0, 4, "maps = \"old.exr\"\nthin_epidermis_mm = 0.07");
    let thin = thin_of(&scene).expect("thin texels");
    assert!(
        (thin.thickness_mm - 0.07).abs() < 1e-7,
        "{}",
        thin.thickness_mm
    );
}

/// The thin-epidermis map of `scene`'s first material, a skin with chromophore maps.
fn thin_of(scene: &Scene) -> Option<render::material::maps::ThinEpidermisMap> {
    let Material::Skin(skin) = &scene.materials[0] else {
        panic!("skin");
    };
    skin.maps.as_ref().expect("maps").maps.thin().cloned()
}

/// `fit_maps` hands its thin-epidermis flag to the renderer: a 2 × 1 PNG of a skin of the exact
/// model under a 0.05 mm epidermis with C_h 0.15 (beyond the normal skin's gamut, as the lips;
/// 8-bit sRGB) beside a skin of the default epidermis (C_m 0.02, C_h 0.02) gives the first texel
/// the thin epidermis (0.05 mm, the fit's default) and not the second; with `thin_epidermis =
/// false` the flag is dropped and the fit kept.
#[test]
fn fit_maps_flags_its_thin_texels() {
    use skin_fit::ColourModel;
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let base = skin_fit::FitOptions::default().base;
    let rgb: Vec<u8> = [(0.05, [0.02, 0.6, 0.15]), (0.25, [0.02, 0.6, 0.02])]
        .iter()
        .flat_map(|(mm, p)| {
            let params = base.with_epidermis_thickness_mm(*mm).unwrap();
            let model = ColourModel::new(10.0, multipole::Method::Exact, params).unwrap();
            let skin = model.skin(p[0], p[1], p[2]).unwrap();
            let linear = model.xyz(&skin).unwrap().to_linear_srgb().0;
            linear.map(|c| (skin_optics::color::srgb_encode(c) * 255.0).round() as u8)
        })
        .collect();
    image::RgbImage::from_raw(2, 1, rgb)
        .unwrap()
        .save(d.join("albedo.png"))
        .unwrap();
    let load = |keys: &str| {
        strip_scene(
            d,
            1.0,
            4,
            &format!("albedo_texture = \"albedo.png\"\nfit_maps = \"1\"\n{keys}"),
        )
    };
    let scene = load("");
    let thin = thin_of(&scene).expect("a thin texel");
    assert!(
        (thin.thickness_mm - 0.05).abs() < 1e-7,
        "{}",
        thin.thickness_mm
    );
    assert!(thin.is_thin(glam::Vec2::new(0.25, 0.5)));
    assert!(!thin.is_thin(glam::Vec2::new(0.75, 0.5)));
    assert!(thin_of(&load("thin_epidermis = false")).is_none());
}
