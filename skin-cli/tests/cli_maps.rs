//! `skin maps` end to end: the files it writes, their channels and flags, edits, and bad input
//! (each a one-line error that leaves no maps.exr behind, or a flagged texel).

use crate::common::stderr;
use skin_fit::ColourModel;
use skin_optics::color::srgb_encode;
use std::path::{Path, PathBuf};
use std::process::Output;
use std::sync::OnceLock;

/// One table cache for every run here: the first builds the forward table, the rest read it.
fn cache_dir() -> &'static Path {
    static DIR: OnceLock<tempfile::TempDir> = OnceLock::new();
    DIR.get_or_init(|| tempfile::tempdir().expect("temp dir"))
        .path()
}

fn skin_maps(args: &[&str]) -> Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_skin"))
        .arg("maps")
        .args(args)
        .env("SKIN_CACHE_DIR", cache_dir())
        .output()
        .expect("run the skin binary")
}

/// Linear Rec.709 of the exact model's skin, as `skin spectrum` prints it.
fn skin_texel(p: [f64; 3]) -> [f32; 3] {
    let m = ColourModel::new(
        10.0,
        multipole::Method::Exact,
        skin_fit::FitOptions::default().base,
    )
    .unwrap();
    let skin = m.skin(p[0], p[1], p[2]).unwrap();
    m.xyz(&skin).unwrap().to_linear_srgb().0.map(|c| c as f32)
}

/// An 8 × 4 texture: the left half skins (C_m along x, C_h along y, β_m 0.6), the right half
/// green, grey, black and white columns.
fn texture() -> Vec<[f32; 3]> {
    let skins: Vec<[f32; 3]> = (0..16)
        .map(|k| {
            let (x, y) = ((k % 4) as f64, (k / 4) as f64);
            skin_texel([0.01 * 3f64.powf(x), 0.6, 0.005 * 2f64.powf(y)])
        })
        .collect();
    let others = [
        [0.05, 0.4, 0.05],
        [0.2, 0.2, 0.2],
        [0.0, 0.0, 0.0],
        [1.0, 1.0, 1.0],
    ];
    (0..32)
        .map(|k| {
            let (x, y) = (k % 8, k / 8);
            if x < 4 {
                skins[y * 4 + x]
            } else {
                others[x - 4]
            }
        })
        .collect()
}

fn write_png16(path: &Path, w: u32, h: u32, texels: &[[f32; 3]]) {
    let raw: Vec<u16> = texels
        .iter()
        .flatten()
        .map(|c| (srgb_encode(f64::from(*c).clamp(0.0, 1.0)) * 65535.0).round() as u16)
        .collect();
    image::ImageBuffer::<image::Rgb<u16>, _>::from_raw(w, h, raw)
        .unwrap()
        .save(path)
        .unwrap();
}

fn write_exr(path: &Path, w: usize, h: usize, texels: &[[f32; 3]]) {
    exr::prelude::write_rgb_file(path, w, h, |x, y| {
        let t = texels[y * w + x];
        (t[0], t[1], t[2])
    })
    .unwrap();
}

/// Every channel of maps.exr, by name.
fn read_maps(dir: &Path) -> std::collections::BTreeMap<String, Vec<f32>> {
    use exr::prelude::*;
    let img = read_all_flat_layers_from_file(dir.join("maps.exr")).unwrap();
    img.layer_data[0]
        .channel_data
        .list
        .iter()
        .map(|c| {
            let values = c.sample_data.values_as_f32().collect();
            (c.name.to_string(), values)
        })
        .collect()
}

/// Run `skin maps --albedo input --out out ARGS`, assert that it succeeds, and return its stderr.
fn maps_of(input: &Path, out: &Path, args: &[&str]) -> String {
    let mut all = vec![
        "--albedo",
        input.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    all.extend_from_slice(args);
    let o = skin_maps(&all);
    assert!(o.status.success(), "{}", stderr(&o));
    stderr(&o)
}

fn out_dir(tag: &str) -> (tempfile::TempDir, PathBuf) {
    let t = tempfile::tempdir().unwrap();
    let d = t.path().join(tag);
    (t, d)
}

#[test]
fn a_texture_becomes_maps_previews_and_albedo() {
    let (tmp, out) = out_dir("maps");
    let png = tmp.path().join("albedo.png");
    write_png16(&png, 8, 4, &texture());
    let err = maps_of(&png, &out, &["--eumelanin", "0.6"]);
    assert!(err.contains("32 fitted, 16 in gamut"), "{err}");
    assert!(err.contains("eumelanin β_m 0.600 (given)"), "{err}");
    let maps = read_maps(&out);
    let names: Vec<&str> = maps.keys().map(String::as_str).collect();
    assert_eq!(
        names,
        ["delta_e", "eumelanin", "hemoglobin", "in_gamut", "melanin"]
    );
    for k in 0..32 {
        let skin = k % 8 < 4;
        assert_eq!(
            maps["in_gamut"][k],
            if skin { 1.0 } else { 0.0 },
            "texel {k}"
        );
        assert!(maps.values().all(|c| c[k].is_finite()));
        if skin {
            // The 16-bit encoding and the interpolant leave well under 0.1 ΔE2000.
            assert!(
                maps["delta_e"][k] < 0.1,
                "texel {k}: {}",
                maps["delta_e"][k]
            );
            let want = 0.01 * 3f32.powi((k % 8) as i32);
            assert!((maps["melanin"][k] / want - 1.0).abs() < 0.03, "texel {k}");
        }
    }
    assert!(maps["eumelanin"].iter().all(|b| *b == 0.6));
    for name in ["albedo.png", "melanin.png", "hemoglobin.png", "delta_e.png"] {
        let img = image::open(out.join(name)).unwrap();
        if name == "albedo.png" {
            assert_eq!((img.width(), img.height()), (8, 4));
        }
    }
    let left = skin_io::atomic::leftovers(
        &out,
        &[
            "maps.exr",
            "albedo.png",
            "melanin.png",
            "hemoglobin.png",
            "delta_e.png",
        ],
    );
    assert!(left.is_empty(), "{left:?}");
}

/// Doubling melanin darkens every skin texel of albedo.png; the identity edit reproduces the
/// input's 8-bit codes within 2.
#[test]
fn edits_retone_the_albedo() {
    let (tmp, out) = out_dir("edit");
    let png = tmp.path().join("albedo.png");
    write_png16(&png, 8, 4, &texture());
    let run = |edit: &str| {
        maps_of(&png, &out, &["--eumelanin", "0.6", "--edit", edit]);
        image::open(out.join("albedo.png")).unwrap().to_rgb8()
    };
    let same = run("melanin*1");
    let input: Vec<u8> = texture()
        .iter()
        .flatten()
        .map(|c| (srgb_encode(f64::from(*c).clamp(0.0, 1.0)) * 255.0).round() as u8)
        .collect();
    for (k, (a, b)) in same.as_raw().iter().zip(&input).enumerate() {
        if (k / 3) % 8 < 4 {
            assert!(
                a.abs_diff(*b) <= 2,
                "texel {} channel {}: {a} vs {b}",
                k / 3,
                k % 3
            );
        }
    }
    let dark = run("melanin*2");
    let sum = |p: &image::Rgb<u8>| p.0.iter().map(|c| u32::from(*c)).sum::<u32>();
    for (k, (d, s)) in dark.pixels().zip(same.pixels()).enumerate() {
        if k % 8 < 4 {
            assert!(sum(d) < sum(s), "texel {k}: {d:?} !< {s:?}");
        }
    }
}

/// A photograph 1.25× brighter than the albedo (16-bit, so within 1e-4 of it): `--exposure 0.8`
/// brings every skin texel back in gamut with its melanin within 3 %, the summary names the gains,
/// and the non-skin texels stay out.
#[test]
fn exposure_scales_a_brighter_photograph_back() {
    let (tmp, out) = out_dir("exposure");
    let png = tmp.path().join("bright.png");
    let bright: Vec<[f32; 3]> = texture()
        .iter()
        .enumerate()
        .map(|(k, t)| if k % 8 < 4 { t.map(|c| c * 1.25) } else { *t })
        .collect();
    write_png16(&png, 8, 4, &bright);
    let err = maps_of(&png, &out, &["--eumelanin", "0.6", "--exposure", "0.8"]);
    assert!(err.contains("32 fitted, 16 in gamut"), "{err}");
    assert!(
        err.contains("gains R 0.800, G 0.800, B 0.800 on every texel (given)"),
        "{err}"
    );
    let maps = read_maps(&out);
    for k in (0..32).filter(|k| k % 8 < 4) {
        assert_eq!(
            maps["in_gamut"][k], 1.0,
            "texel {k}: {}",
            maps["delta_e"][k]
        );
        let want = 0.01 * 3f32.powi((k % 8) as i32);
        assert!((maps["melanin"][k] / want - 1.0).abs() < 0.03, "texel {k}");
    }
}

/// `--eumelanin-regions 4` on the 8 × 4 texture: two regions, the eumelanin channel constant
/// within each and in [0, 1], the summary names the regions, and the skins stay in gamut.
#[test]
fn eumelanin_per_region_fills_the_channel() {
    let (tmp, out) = out_dir("regions");
    let png = tmp.path().join("albedo.png");
    write_png16(&png, 8, 4, &texture());
    let err = maps_of(&png, &out, &["--eumelanin-regions", "4"]);
    assert!(
        err.contains("per region of 4×4 texels (2 regions)"),
        "{err}"
    );
    let maps = read_maps(&out);
    let b = &maps["eumelanin"];
    for k in 0..32 {
        assert!((0.0..=1.0).contains(&b[k]), "texel {k}: {}", b[k]);
        assert_eq!(b[k], b[if k % 8 < 4 { 0 } else { 4 }], "texel {k}");
        if k % 8 < 4 {
            assert_eq!(
                maps["in_gamut"][k], 1.0,
                "texel {k}: {}",
                maps["delta_e"][k]
            );
        }
    }
}

/// Bad `--exposure` and `--model` values are usage errors naming the valid ones.
#[test]
fn bad_exposure_and_model_are_usage_errors() {
    for (flag, value, want) in [
        ("--exposure", "3", "outside [0.125, 2]"),
        ("--exposure", "0.5,0.6", "is not G, R,G,B, auto or auto-rgb"),
        ("--exposure", "bright", "[0.125, 2]"),
        ("--model", "tiny", "valid: seed, full, auto"),
        ("--eumelanin-regions", "2", "4..=4096"),
        ("--thin-epidermis", "0.5", "outside [0.04, 0.3] mm"),
        ("--thin-epidermis", "thin", "[0.04, 0.3] mm"),
        ("--thin-hemoglobin-max", "1.5", "outside (0.001, 1]"),
        ("--parameters", "gloss", "one of epidermis_blood"),
    ] {
        let o = skin_maps(&["--albedo", "x.png", flag, value]);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{flag} {value}: {}", err);
        assert!(err.contains(want), "{flag} {value}: {}", err);
    }
}

/// `--model full` over one extended parameter: skins made with a Mie scale of 1.5 get it back
/// within 5 % (candidates 0.375 apart and a parabola between them, the library test's bound),
/// written as its own maps.exr channel named as in `skin fit --json`, and the maps of that skin
/// reproduce every texel in gamut.
#[test]
fn an_extended_parameter_becomes_its_own_channel() {
    let mie = skin_fit::Parameter::CANDIDATES
        .into_iter()
        .find(|p| p.name() == "mie_scale")
        .unwrap();
    let base = mie.set(skin_fit::FitOptions::default().base, 1.5).unwrap();
    let m = ColourModel::new(10.0, multipole::Method::Exact, base).unwrap();
    let texels: Vec<[f32; 3]> = (0..16)
        .map(|k| {
            let (x, y) = ((k % 4) as f64, (k / 4) as f64);
            let skin = m
                .skin(0.01 * 3f64.powf(x), 0.6, 0.005 * 2f64.powf(y))
                .unwrap();
            m.xyz(&skin).unwrap().to_linear_srgb().0.map(|c| c as f32)
        })
        .collect();
    let (tmp, out) = out_dir("extended");
    let exr = tmp.path().join("albedo.exr");
    write_exr(&exr, 4, 4, &texels);
    let err = maps_of(
        &exr,
        &out,
        &[
            "--eumelanin",
            "0.6",
            "--model",
            "full",
            "--parameters",
            "mie_scale",
        ],
    );
    let maps = read_maps(&out);
    let mie = maps.get("mie_scale").expect("a mie_scale channel");
    assert!(mie.iter().all(|v| (v / 1.5 - 1.0).abs() <= 0.05), "{mie:?}");
    assert!(maps["in_gamut"].iter().all(|g| *g == 1.0), "{}", err);
    assert!(!maps.contains_key("bilirubin_g_per_l"));
}

/// NaN and negative texels of an EXR are fitted as replaced values and flagged, not an error.
#[test]
fn bad_exr_texels_are_flagged() {
    let (tmp, out) = out_dir("exr");
    let exr = tmp.path().join("albedo.exr");
    let mut t = texture();
    t[0] = [f32::NAN, 0.2, 0.1];
    t[1] = [-0.5, 0.2, 0.1];
    write_exr(&exr, 8, 4, &t);
    let err = maps_of(&exr, &out, &["--eumelanin", "0.6"]);
    assert!(err.contains("2 bad values replaced"), "{}", err);
    let maps = read_maps(&out);
    assert_eq!(&maps["in_gamut"][..3], [0.0, 0.0, 1.0]);
    assert!(maps.values().flatten().all(|v| v.is_finite()));
}

/// A PNG whose header declares `w` × `h` (valid signature, IHDR and CRCs; no image data).
fn png_header(w: u32, h: u32) -> Vec<u8> {
    fn crc32(bytes: &[u8]) -> u32 {
        let mut c = !0u32;
        for b in bytes {
            c ^= u32::from(*b);
            for _ in 0..8 {
                c = if c & 1 == 1 {
                    0xEDB8_8320 ^ (c >> 1)
                } else {
                    c >> 1
                };
            }
        }
        !c
    }
    let mut chunk = b"IHDR".to_vec();
    chunk.extend_from_slice(&w.to_be_bytes());
    chunk.extend_from_slice(&h.to_be_bytes());
    chunk.extend_from_slice(&[8, 2, 0, 0, 0]);
    let mut out = b"\x89PNG\r\n\x1a\n".to_vec();
    out.extend_from_slice(&13u32.to_be_bytes());
    out.extend_from_slice(&chunk);
    out.extend_from_slice(&crc32(&chunk).to_be_bytes());
    // An empty IDAT: the decoder reads the header up to the first image data chunk.
    out.extend_from_slice(&0u32.to_be_bytes());
    out.extend_from_slice(b"IDAT");
    out.extend_from_slice(&crc32(b"IDAT").to_be_bytes());
    out
}

#[test]
fn bad_input_is_one_line_and_leaves_no_maps() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let good = dir.join("good.png");
    write_png16(&good, 8, 4, &texture());
    let small = dir.join("small.png");
    write_png16(&small, 4, 4, &texture()[..16]);
    let head =
        std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("../render/assets/Map-COL.jpg"))
            .unwrap();
    let cut_jpeg = dir.join("cut.jpg");
    std::fs::write(&cut_jpeg, &head[..head.len() / 2]).unwrap();
    let cut_png = dir.join("cut.png");
    let png = std::fs::read(&good).unwrap();
    std::fs::write(&cut_png, &png[..png.len() / 2]).unwrap();
    let huge = dir.join("huge.png");
    std::fs::write(&huge, png_header(100_000, 100_000)).unwrap();
    let text = dir.join("text.png");
    std::fs::write(&text, b"not an image").unwrap();
    let g = good.to_str().unwrap();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec!["--albedo", "/nonexistent/albedo.png"],
            "cannot be read",
        ),
        (vec!["--albedo", cut_jpeg.to_str().unwrap()], "JPEG"),
        (vec!["--albedo", cut_png.to_str().unwrap()], "cut.png"),
        (vec!["--albedo", huge.to_str().unwrap()], "over the cap"),
        (vec!["--albedo", text.to_str().unwrap()], "text.png"),
        (vec!["--albedo", "Cargo.toml"], "expected a"),
        (
            vec!["--albedo", g, "--mask", small.to_str().unwrap()],
            "must match",
        ),
        (
            vec![
                "--albedo",
                g,
                "--edit-mask",
                small.to_str().unwrap(),
                "--edit",
                "hemoglobin*2",
            ],
            "must match",
        ),
    ];
    for (args, want) in cases {
        let out = dir.join("out");
        let mut all = args.clone();
        all.extend(["--out", out.to_str().unwrap(), "--eumelanin", "0.6"]);
        let o = skin_maps(&all);
        let err = stderr(&o);
        assert!(!o.status.success(), "{args:?} succeeded");
        assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
        assert!(
            err.starts_with("error: ") && err.trim_end().lines().count() == 1,
            "{args:?}: {err}"
        );
        assert!(err.contains(want), "{args:?}: {err}");
        assert!(!out.join("maps.exr").exists(), "{args:?} left a maps.exr");
    }
    // Bad edits are refused by the argument parser (usage error, code 2).
    for edit in ["melanin/2", "eumelanin=2", "blood*2"] {
        let o = skin_maps(&["--albedo", g, "--edit", edit]);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{edit}: {}", err);
        assert!(
            err.contains("melanin*S") || err.contains("[0, 1]"),
            "{}",
            err
        );
    }
}

/// Texels out of the texture skin's gamut that the thin-epidermis skin reproduces (a skin of the
/// exact model under 0.05 mm with C_h 0.15, as the lips) are flagged in maps.exr's
/// `thin_epidermis` channel, and the file records the thickness they were fitted under in its
/// `thin_epidermis_mm` attribute (`--thin-epidermis 0.06` here), which the renderer and the
/// textured export read with it.
#[test]
fn thin_epidermis_texels_carry_their_thickness() {
    let base = skin_fit::FitOptions::default().base;
    let thin = base.with_epidermis_thickness_mm(0.06).unwrap();
    let m = ColourModel::new(10.0, multipole::Method::Exact, thin).unwrap();
    let skin = m.skin(0.02, 0.6, 0.15).unwrap();
    let red = m.xyz(&skin).unwrap().to_linear_srgb().0.map(|c| c as f32);
    let normal = skin_texel([0.02, 0.6, 0.02]);
    let (tmp, out) = out_dir("thin");
    let exr = tmp.path().join("albedo.exr");
    write_exr(&exr, 2, 1, &[red, normal]);
    maps_of(
        &exr,
        &out,
        &["--eumelanin", "0.6", "--thin-epidermis", "0.06"],
    );
    let bytes = std::fs::read(out.join("maps.exr")).unwrap();
    let maps = render::material::maps::read_maps_exr(&bytes, &out.join("maps.exr")).unwrap();
    assert_eq!(maps.thin_epidermis.unwrap().values, vec![1.0, 0.0]);
    let mm = maps.thin_epidermis_mm.expect("the thickness attribute");
    assert!((mm - 0.06).abs() < 1e-7, "{mm}");
    // The textured export fits the flagged texel under the thickness the file records.
    let mtlx = tmp.path().join("mat").join("skin.mtlx");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_skin"))
        .args(["export", "openpbr", "--maps"])
        .arg(out.join("maps.exr"))
        .arg("--out")
        .arg(&mtlx)
        .args(crate::common::QUICK_EXPORT)
        .env("SKIN_CACHE_DIR", cache_dir())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("for the 1 texels under a 0.060 mm epidermis"),
        "{}",
        stderr(&o)
    );
}
