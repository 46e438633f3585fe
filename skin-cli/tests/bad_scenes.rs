//! Bad scene files fail with a message naming the file, the key (or path) and what was expected,
//! and `skin render` writes no image.

use crate::common;

use clap::Parser;
use skin_cli::render::{RenderArgs, run};
use std::path::PathBuf;

#[derive(Parser)]
struct Cli {
    #[command(flatten)]
    args: RenderArgs,
}

/// A scene that loads and renders: a skin sphere seen from 300 mm.
fn good() -> String {
    common::SceneText::camera([0.0, 0.0, 300.0], 30.0)
        .skin("skin", "preset = \"light\"")
        .mesh("sphere", "skin", 50.0)
        .with("translate_mm = [0, 0, 0]")
        .text()
        .to_string()
}

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("skin-bad-scene-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Run `skin render` on `text`; return the error message and check no image was written.
fn render_text(name: &str, text: &str) -> Result<(), String> {
    let d = dir(name);
    let scene = d.join("scene.toml");
    std::fs::write(&scene, text).unwrap();
    let out = d.join("out");
    let cli = Cli::parse_from([
        "render",
        "--scene",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--width",
        "8",
        "--height",
        "8",
        "--spp",
        "1",
        "--quiet",
    ]);
    let r = run(&cli.args).map_err(|e| format!("{e:#}"));
    if r.is_err() {
        for f in [
            "render.png",
            "render.exr",
            "render.png.tmp",
            "render.exr.tmp",
        ] {
            assert!(!out.join(f).exists(), "{f} written for a bad scene");
        }
    }
    std::fs::remove_dir_all(&d).unwrap();
    r
}

fn assert_mentions(err: &str, parts: &[&str]) {
    for p in parts {
        assert!(err.contains(p), "error {err:?} does not mention {p:?}");
    }
}

#[test]
fn the_good_scene_renders() {
    render_text("good", &good()).unwrap();
}

#[test]
fn unknown_key_is_named() {
    let text = good().replace("fov_deg = 30", "fov_deg = 30\nzoom = 2");
    let e = render_text("unknown", &text).unwrap_err();
    assert_mentions(&e, &["scene.toml", "zoom", "unknown field"]);
}

#[test]
fn missing_mesh_names_its_path() {
    let text = good().replace("shape = \"sphere\"", "file = \"no_such_head.glb\"");
    let e = render_text("missing", &text).unwrap_err();
    assert_mentions(&e, &["mesh", "no_such_head.glb"]);
    assert_mentions(&e, &["cannot be read"]);
}

#[test]
fn invalid_skin_parameter_is_named() {
    let text = good().replace("preset = \"light\"", "preset = \"light\"\nmelanin = 1.5");
    let e = render_text("skin", &text).unwrap_err();
    assert_mentions(
        &e,
        &["scene.toml", "materials.skin.melanin", "1.5", "[0, 1]"],
    );
}

#[test]
fn non_finite_transform_is_named() {
    let text = good().replace("translate_mm = [0, 0, 0]", "translate_mm = [nan, 0, 0]");
    let e = render_text("nan", &text).unwrap_err();
    // Refused while parsing, on one line with its position (1-based, at the bad value).
    let at = |text: &str, key: &str, column: usize| {
        let line = text.lines().position(|l| l.starts_with(key)).unwrap() + 1;
        format!("line {line}, column {column}")
    };
    assert_mentions(
        &e,
        &["scene.toml", &at(&text, "translate_mm", 16), "finite"],
    );
    assert!(!e.contains('\n'), "{e}");
    let text = good().replace("scale = 50", "scale = inf");
    let e = render_text("inf", &text).unwrap_err();
    assert_mentions(&e, &[&at(&text, "scale", 9), "finite"]);
}

#[test]
fn geometry_placed_beyond_2e19_mm_is_named() {
    for (case, placement) in [
        ("scale", "scale = 1e25"),
        ("translate", "scale = 50\ntranslate_mm = [3e38, 0, 0]"),
        ("units", "scale = 50\nunits_mm = 2e19"),
    ] {
        let text = good()
            .replace("translate_mm = [0, 0, 0]", "")
            .replace("scale = 50", placement);
        let e = render_text(case, &text).unwrap_err();
        assert_mentions(&e, &["scene.toml", "meshes[0]", "±1e9 mm"]);
    }
}

#[test]
fn dev_zero_as_scene_mesh_texture_or_environment_is_refused_before_reading() {
    let good = good();
    let cli = Cli::parse_from(["render", "--scene", "/dev/zero", "--quiet"]);
    let e = format!("{:#}", run(&cli.args).unwrap_err());
    assert_mentions(&e, &["/dev/zero", ".toml"]);
    let mesh = good.replace("shape = \"sphere\"", "file = \"/dev/zero\"");
    let e = render_text("zero-mesh", &mesh).unwrap_err();
    assert_mentions(&e, &["/dev/zero", ".glb or .obj"]);
    let env = format!("{good}\n[environment]\nexr = \"/dev/zero\"\nintensity = 1\n");
    let e = render_text("zero-env", &env).unwrap_err();
    assert_mentions(&e, &["/dev/zero", ".exr"]);
}

#[test]
fn toml_errors_take_one_line() {
    let e = render_text("toml", "[camera\n").unwrap_err();
    assert_mentions(&e, &["scene.toml", "line 1"]);
    assert!(!e.contains('\n'), "{e}");
}

#[test]
fn unknown_material_and_bad_light_are_named() {
    let good = good();
    let text = good.replace("material = \"skin\"", "material = \"bone\"");
    let e = render_text("material", &text).unwrap_err();
    assert_mentions(&e, &["meshes[0].material", "bone"]);
    let text = format!(
        "{good}\n[[lights]]\ntype = \"sphere\"\ncenter_mm = [0, 0, 200]\nradius_mm = -1\nintensity = 1\n"
    );
    let e = render_text("light", &text).unwrap_err();
    assert_mentions(&e, &["lights[0].radius_mm", "(0, 1e9] mm"]);
}

/// Light sizes, positions and intensities beyond what f32 transport can carry are typed errors
/// naming the key and its range (they used to pass and turn every selection weight into inf or
/// NaN, which silently switched light sampling off).
#[test]
fn huge_light_parameters_are_named_with_their_range() {
    let good = good();
    let quad = "type = \"quad\"\ncenter_mm = [0, 0, 200]\nlook_at_mm = [0, 0, 0]\nintensity = 1";
    let sphere = "type = \"sphere\"\ncenter_mm = [0, 0, 200]\nintensity = 1";
    let cases = [
        (
            format!("{quad}\nsize_mm = [1e20, 1e20]"),
            "lights[0].size_mm",
            "(0, 1e9] mm",
        ),
        (
            format!("{sphere}\nradius_mm = 3e19"),
            "lights[0].radius_mm",
            "(0, 1e9] mm",
        ),
        (
            format!("{sphere}\nradius_mm = 10").replace("intensity = 1", "intensity = 3e38"),
            "lights[0].intensity",
            "[0, 1e30]",
        ),
        (
            format!("{sphere}\nradius_mm = 10").replace("[0, 0, 200]", "[3e38, 0, 0]"),
            "lights[0].center_mm",
            "1e9 mm",
        ),
    ];
    for (i, (light, key, range)) in cases.iter().enumerate() {
        let text = format!("{good}\n[[lights]]\n{light}\n");
        let e = render_text(&format!("huge{i}"), &text).unwrap_err();
        assert_mentions(&e, &[key, range, "scene.toml"]);
    }
    let text = format!("{good}\n[environment]\nintensity = 3e38\n");
    let e = render_text("huge-env", &text).unwrap_err();
    assert_mentions(&e, &["environment.intensity", "[0, 1e30]"]);
}

/// A distant light's direction whose squared length overflows f32 is still a direction: the
/// scene loads with a unit `to_light` and the sphere it shines on is lit.
#[test]
fn distant_direction_3e38_normalises_and_lights_the_scene() {
    let good = good();
    let text = format!(
        "{good}\n[[lights]]\ntype = \"distant\"\ndirection = [3e38, 3e38, 3e38]\nintensity = 1\n"
    )
    .replace(
        "type = \"skin\"\npreset = \"light\"",
        "type = \"diffuse\"\nalbedo = 0.5",
    );
    let scene = common::scene(&text);
    let render::light::Light::Distant(d) = &scene.lights[0] else {
        panic!("{:?}", scene.lights[0]);
    };
    assert!((d.to_light - glam::Vec3::splat(1.0 / 3f32.sqrt())).length() < 1e-6);
    let y = common::mean_xyz(&common::run(&scene, 8, 8, 4, 1))[1];
    assert!(y.is_finite() && y > 0.0, "{y}");
}
