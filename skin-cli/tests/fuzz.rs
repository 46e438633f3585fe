//! Fuzzing on stable Rust with proptest strategies: scene TOML, spectrum CSV, OBJ and GLB bytes
//! and EXR headers, each fed to its reader. Every input must end in `Ok` or a one-line typed
//! error: a panic is a crash, and the test fails on any.
//!
//! CI runs `FUZZ_CASES` inputs per kind (default 48). A long campaign, printing the table that
//! BENCHMARKS.md quotes:
//!
//! ```text
//! FUZZ_CASES=5000 FUZZ_SEED=1 cargo test -p skin-cli --release --test main fuzz -- --nocapture --include-ignored
//! ```

use crate::common;

use proptest::prelude::*;
use proptest::strategy::ValueTree;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
use render::material::SkinKnobs;
use render::mesh::{TriangleMesh, glb_container};
use render::renderer::{RenderOptions, render};
use render::scene::Scene;
use render::texture::Texture;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;

/// Numbers a hostile user tries: mostly ordinary (so that whole scenes load and render), else
/// tiny, huge, beyond f32, non-finite, negative or not a number at all.
fn number() -> impl Strategy<Value = String> {
    prop_oneof![
        240 => (0.5f64..100.0).prop_map(|v| format!("{v}")),
        1 => Just("0".to_string()),
        1 => Just("-1".to_string()),
        1 => Just("1e-30".to_string()),
        1 => Just("1e20".to_string()),
        1 => Just("3e38".to_string()),
        1 => Just("1e39".to_string()),
        1 => Just("1e308".to_string()),
        1 => Just("inf".to_string()),
        1 => Just("-inf".to_string()),
        1 => Just("nan".to_string()),
        1 => Just("\"junk\"".to_string()),
    ]
}

/// A fraction: mostly in [0, 1], else hostile.
fn fraction() -> impl Strategy<Value = String> {
    prop_oneof![
        20 => (0.0f64..=1.0).prop_map(|v| format!("{v}")),
        1 => number(),
    ]
}

/// An array of 0–5 numbers (3 most of the time).
fn array() -> impl Strategy<Value = String> {
    prop_oneof![
        40 => prop::collection::vec(number(), 3..=3),
        1 => prop::collection::vec(number(), 0..=5),
    ]
    .prop_map(|v| format!("[{}]", v.join(", ")))
}

fn light() -> impl Strategy<Value = String> {
    (0..5usize, array(), array(), number(), number(), number(), array()).prop_map(
        |(kind, a, b, x, y, intensity, size)| match kind {
            0 => format!("[[lights]]\ntype = \"point\"\nposition_mm = {a}\nintensity = {intensity}\n"),
            1 => format!(
                "[[lights]]\ntype = \"spot\"\nposition_mm = {a}\nlook_at_mm = {b}\ninner_deg = {x}\nouter_deg = {y}\nintensity = {intensity}\n"
            ),
            2 => format!("[[lights]]\ntype = \"distant\"\ndirection = {a}\nintensity = {intensity}\n"),
            3 => format!(
                "[[lights]]\ntype = \"sphere\"\ncenter_mm = {a}\nradius_mm = {x}\nspectrum = \"blackbody\"\ntemperature_k = {y}\nintensity = {intensity}\n"
            ),
            _ => format!(
                "[[lights]]\ntype = \"quad\"\ncenter_mm = {a}\nlook_at_mm = {b}\nsize_mm = {size}\nintensity = {intensity}\n"
            ),
        },
    )
}

fn material() -> impl Strategy<Value = String> {
    let rgb = prop::collection::vec(fraction(), 3..=3).prop_map(|v| format!("[{}]", v.join(", ")));
    (0..4usize, fraction(), rgb, number()).prop_map(|(kind, x, rgb, nm)| match kind {
        0 => format!("[materials.m]\ntype = \"diffuse\"\nalbedo = {x}\n"),
        1 => format!("[materials.m]\ntype = \"diffuse\"\nalbedo_srgb = {rgb}\n"),
        2 => format!(
            "[materials.m]\ntype = \"diffuse\"\nalbedo_spectrum = [[400, 0.5], [{}, 0.5], [700, {x}]]\n",
            400.0 + nm.parse::<f64>().map_or(1000.0, |v| v * 3.0)
        ),
        _ => format!("[materials.m]\ntype = \"skin\"\nmelanin = {x}\nroughness = {x}\n"),
    })
}

/// A scene: camera, film, environment, one material, one placed shape and 0–2 lights, each value
/// drawn from [`number`]; sometimes a few bytes of it are then overwritten.
fn scene_text() -> impl Strategy<Value = String> {
    let camera = (array(), array(), array(), number(), number(), number())
        .prop_map(|(p, l, u, fov, ap, f)| {
            format!(
                "[camera]\nposition_mm = {p}\nlook_at_mm = {l}\nup = {u}\nfov_deg = {fov}\naperture_mm = {ap}\nfocus_distance_mm = {f}\n"
            )
        });
    let placed = (0..2usize, number(), number(), array(), array()).prop_map(
        |(shape, units, scale, rot, tr)| {
            let shape = ["sphere", "quad"][shape];
            format!(
                "[[meshes]]\nshape = \"{shape}\"\nmaterial = \"m\"\nunits_mm = {units}\nscale = {scale}\nrotate_deg = {rot}\ntranslate_mm = {tr}\n"
            )
        },
    );
    let env = (number(), number()).prop_map(|(i, e)| {
        format!("[film]\nexposure_stops = {e}\n[environment]\nintensity = {i}\n")
    });
    (
        camera,
        env,
        material(),
        placed,
        prop::collection::vec(light(), 0..=2),
        prop::option::weighted(0.2, (any::<usize>(), any::<u8>())),
    )
        .prop_map(|(c, e, m, p, lights, flip)| {
            let mut text = format!("{c}{e}{m}{p}{}", lights.concat()).into_bytes();
            if let Some((at, byte)) = flip {
                let n = text.len();
                text[at % n] = byte;
            }
            String::from_utf8_lossy(&text).into_owned()
        })
}

fn csv_text() -> impl Strategy<Value = String> {
    let header = prop_oneof![
        Just("lambda_nm,reflectance\n".to_string()),
        Just("\u{feff}lambda_nm,reflectance,weight\n".to_string()),
        Just("lambda_nm,reflectance,weight\n".to_string()),
        Just("nm;r\n".to_string()),
    ];
    // Mostly well-formed rows on increasing wavelengths; sometimes a hostile field or count.
    let good = (0.0f64..=1.0, 0.0f64..10.0).prop_map(|(r, w)| (r, w));
    let bad = prop::collection::vec(number(), 1..=4).prop_map(|f| f.join(","));
    let row = prop_oneof![30 => good.prop_map(|g| (Some(g), String::new())), 1 => bad.prop_map(|b| (None, b))];
    (header, prop::collection::vec(row, 0..40)).prop_map(|(h, rows)| {
        let three = h.contains("weight");
        let n = rows.len().max(1) as f64;
        let body: Vec<String> = rows
            .iter()
            .enumerate()
            .map(|(i, (good, bad))| match good {
                Some((r, w)) => {
                    let nm = 400.0 + 300.0 * i as f64 / n;
                    if three {
                        format!("{nm},{r},{w}\n")
                    } else {
                        format!("{nm},{r}\n")
                    }
                }
                None => format!("{bad}\n"),
            })
            .collect();
        h + &body.concat()
    })
}

fn obj_text() -> impl Strategy<Value = String> {
    let line = prop_oneof![
        3 => prop::collection::vec(number(), 3..=3).prop_map(|v| format!("v {}\n", v.join(" "))),
        1 => prop::collection::vec(number(), 2..=2).prop_map(|v| format!("vt {}\n", v.join(" "))),
        1 => prop::collection::vec(number(), 3..=3).prop_map(|v| format!("vn {}\n", v.join(" "))),
        3 => prop::collection::vec(prop_oneof![20 => 1i64..6, 1 => -3i64..12], 3..=4).prop_map(|v| {
            let v: Vec<String> = v.iter().map(i64::to_string).collect();
            format!("f {}\n", v.join(" "))
        }),
    ];
    prop::collection::vec(line, 0..30).prop_map(|l| l.concat())
}

/// A GLB: random node hierarchy (children may point anywhere, cycles included), accessor counts,
/// buffer view ranges and component types over a small binary buffer.
fn glb_bytes() -> impl Strategy<Value = Vec<u8>> {
    let node = (
        prop::option::of(0..2usize),
        prop::collection::vec(0..6usize, 0..3),
    );
    (
        prop::collection::vec(node, 1..6),
        0usize..200,
        0usize..100,
        prop::sample::select(vec![5121u32, 5123, 5125, 5126]),
        prop::collection::vec(any::<u8>(), 0..128),
        any::<bool>(),
    )
        .prop_map(|(nodes, pos_count, idx_count, idx_type, bin, normals)| {
            // Children point at existing nodes (any of them: cycles and shared children included).
            let n = nodes.len();
            let nodes: Vec<String> = nodes
                .iter()
                .map(|(mesh, children)| {
                    let mut fields = vec![];
                    if let Some(m) = mesh {
                        fields.push(format!("\"mesh\":{m}"));
                    }
                    if !children.is_empty() {
                        let c: Vec<String> = children.iter().map(|c| (c % n).to_string()).collect();
                        fields.push(format!("\"children\":[{}]", c.join(",")));
                    }
                    format!("{{{}}}", fields.join(","))
                })
                .collect();
            let nodes = nodes.join(",");
            let normal = if normals { ",\"NORMAL\":0" } else { "" };
            let json = format!(
                r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{nodes}],
                "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0{normal}}},"indices":1}}]}},{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],
                "buffers":[{{"byteLength":{len}}}],
                "bufferViews":[{{"buffer":0,"byteLength":{len}}}],
                "accessors":[{{"bufferView":0,"componentType":5126,"count":{pos_count},"type":"VEC3","min":[0,0,0],"max":[1,1,1]}},
                             {{"bufferView":0,"componentType":{idx_type},"count":{idx_count},"type":"SCALAR"}}]}}"#,
                len = bin.len()
            );
            glb_container(&json, &bin)
        })
}

/// A valid 2×2 EXR written by the `exr` crate with bytes of its header overwritten.
fn exr_bytes() -> impl Strategy<Value = Vec<u8>> {
    let base = common::grey_exr_2x2();
    let header_len = base.len().min(400);
    prop::collection::vec((0..header_len, any::<u8>()), 1..6).prop_map(move |edits| {
        let mut b = base.clone();
        for (at, v) in edits {
            b[at] = v;
        }
        b
    })
}

/// What happened to one input.
#[derive(Default)]
struct Tally {
    tried: usize,
    accepted: usize,
    clear_errors: usize,
    unclear_errors: usize,
    crashes: usize,
}

impl Tally {
    /// Run `f` on an input: `Ok`, a one-line error, a multi-line or empty error, or a panic.
    fn run(
        &mut self,
        what: &str,
        input: &dyn std::fmt::Debug,
        f: impl FnOnce() -> Result<(), String>,
    ) {
        self.tried += 1;
        match catch_unwind(AssertUnwindSafe(f)) {
            Ok(Ok(())) => self.accepted += 1,
            Ok(Err(e)) if !e.is_empty() && !e.contains('\n') && e.len() < 1000 => {
                self.clear_errors += 1
            }
            Ok(Err(e)) => {
                self.unclear_errors += 1;
                eprintln!("{what}: unclear error {e:?} for {input:?}");
            }
            Err(_) => {
                self.crashes += 1;
                eprintln!("{what}: CRASH for {input:?}");
            }
        }
    }
}

fn runner() -> TestRunner {
    let seed: u64 = std::env::var("FUZZ_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1);
    let mut key = [0u8; 32];
    key[..8].copy_from_slice(&seed.to_le_bytes());
    TestRunner::new_with_rng(
        Config::default(),
        TestRng::from_seed(RngAlgorithm::ChaCha, &key),
    )
}

fn cases() -> usize {
    std::env::var("FUZZ_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(48)
}

/// Draw `cases()` inputs from `strategy` and feed each to `check`.
fn campaign<S: Strategy>(
    what: &str,
    strategy: S,
    check: impl Fn(&S::Value) -> Result<(), String>,
) -> Tally
where
    S::Value: std::fmt::Debug,
{
    let mut runner = runner();
    let mut tally = Tally::default();
    for _ in 0..cases() {
        let input = strategy.new_tree(&mut runner).unwrap().current();
        tally.run(what, &input, || check(&input));
    }
    tally
}

fn load_scene(text: &str) -> Result<(), String> {
    let opts = SkinKnobs {
        method: multipole::Method::Multipole,
        no_subsurface: true,
        ..SkinKnobs::default()
    };
    // Syntax and schema errors as `scene_file::parse` reports them (one line, with the position).
    render::scene_file::parse(text)?;
    let scene = Scene::from_toml(text, "fuzz.toml", None, &opts).map_err(|e| e.to_string())?;
    // Scenes that load are rendered (tiny), so geometry, lights and film see the values too.
    let settings = RenderOptions {
        width: 4,
        height: 3,
        spp: 1,
        threads: Some(1),
        ..RenderOptions::default()
    }
    .validate()
    .map_err(|e| e.to_string())?;
    let (film, _) = render(&scene, &settings).map_err(|e| e.to_string())?;
    for y in 0..3 {
        for x in 0..4 {
            if !film.linear_srgb(x, y).iter().all(|v| v.is_finite()) {
                return Err(format!("non-finite pixel\nat {x},{y}"));
            }
        }
    }
    Ok(())
}

fn print_and_check(rows: &[(&str, Tally)]) {
    println!("| input | tried | accepted | clear errors | unclear errors | crashes |");
    println!("|---|---|---|---|---|---|");
    for (name, t) in rows {
        println!(
            "| {name} | {} | {} | {} | {} | {} |",
            t.tried, t.accepted, t.clear_errors, t.unclear_errors, t.crashes
        );
    }
    for (name, t) in rows {
        assert_eq!(t.crashes, 0, "{name}: crashes");
        assert_eq!(t.unclear_errors, 0, "{name}: multi-line or empty errors");
    }
}

/// Scenes, loaded and rendered.
#[test]
fn fuzzed_scenes_load_and_render_or_give_a_one_line_error() {
    std::panic::set_hook(Box::new(|info| eprintln!("panic: {info}")));
    let rows = [(
        "scene TOML",
        campaign("scene", scene_text(), |t| load_scene(t)),
    )];
    let _ = std::panic::take_hook();
    print_and_check(&rows);
}

#[test]
fn fuzzed_inputs_end_in_ok_or_a_one_line_error_never_a_crash() {
    // Each crash is reported once by the tally; the default hook would print a backtrace for it.
    std::panic::set_hook(Box::new(|info| eprintln!("panic: {info}")));
    let rows = [
        (
            "spectrum CSV",
            campaign("csv", csv_text(), |t| {
                skin_fit::MeasuredSpectrum::parse_csv(t)
                    .map(|_| ())
                    .map_err(|e| e.to_string())
            }),
        ),
        (
            "OBJ",
            campaign("obj", obj_text(), |t| {
                TriangleMesh::from_obj(t.as_bytes(), Path::new("f.obj"))
                    .map(|_| ())
                    .map_err(|e| e.to_string())
            }),
        ),
        (
            "GLB",
            campaign("glb", glb_bytes(), |b| {
                TriangleMesh::from_glb(b, Path::new("f.glb"))
                    .map(|_| ())
                    .map_err(|e| e.to_string())
            }),
        ),
        (
            "EXR header",
            campaign("exr", exr_bytes(), |b| {
                Texture::from_exr_bytes(b, Path::new("f.exr"))
                    .map(|_| ())
                    .map_err(|e| e.to_string())
            }),
        ),
    ];
    let _ = std::panic::take_hook();
    print_and_check(&rows);
}
