//! Hostile input files of under 10 MB, each run through the `skin` binary under `ulimit -v` of
//! 2 GiB: every one must end in a clean error (exit 1 or 2), never an abort, a crash or a kill
//! for memory.

use crate::common;

use std::path::{Path, PathBuf};
use std::process::Command;

/// Address space allowed to the child, KiB (2 GiB).
const LIMIT_KIB: u64 = 2 * 1024 * 1024;

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("skin-memory-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Run `skin ARGS` under the address-space limit; its exit code and stderr.
fn skin_limited(args: &[&str]) -> (Option<i32>, String) {
    let out = Command::new("sh")
        .arg("-c")
        .arg(format!("ulimit -v {LIMIT_KIB}; exec \"$0\" \"$@\""))
        .arg(env!("CARGO_BIN_EXE_skin"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn assert_clean_error(args: &[&str], wanted: &str) {
    let (code, stderr) = skin_limited(args);
    assert!(
        matches!(code, Some(1 | 2)),
        "{args:?}: exit {code:?} (a signal or a panic), stderr {stderr}"
    );
    assert!(stderr.contains(wanted), "{args:?}: {stderr}");
    assert_eq!(stderr.trim_end().lines().count(), 1, "{args:?}: {stderr}");
}

fn scene_with(d: &Path, body: &str) -> String {
    let scene = d.join("scene.toml");
    std::fs::write(
        &scene,
        format!(
            "[camera]\nposition_mm = [0, 0, 300]\nlook_at_mm = [0, 0, 0]\nfov_deg = 30\n\
             [materials.m]\ntype = \"diffuse\"\nalbedo = 0.5\n{body}"
        ),
    )
    .unwrap();
    scene.display().to_string()
}

#[test]
fn dev_zero_as_a_spectrum_is_refused_within_2_gib() {
    assert_clean_error(&["fit", "--spectrum", "/dev/zero"], "expected a .csv file");
    let d = dir("zero-csv");
    let link = d.join("zero.csv");
    let _ = std::fs::remove_file(&link);
    std::os::unix::fs::symlink("/dev/zero", &link).unwrap();
    assert_clean_error(
        &["fit", "--spectrum", &link.display().to_string()],
        "not a regular file",
    );
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn glb_node_dag_with_2_pow_40_paths_is_refused_within_2_gib() {
    let d = dir("dag");
    // Two nodes per level over 40 levels, each parent of both nodes below: 2⁴⁰ paths.
    let nodes: Vec<String> = (0..80)
        .map(|i| match 2 * (i / 2 + 1) {
            n if n < 80 => format!(r#"{{"mesh":0,"children":[{n},{}]}}"#, n + 1),
            _ => r#"{"mesh":0}"#.to_string(),
        })
        .collect();
    let mut bin = Vec::new();
    for c in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
        bin.extend_from_slice(&c.to_le_bytes());
    }
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0,1]}}],"nodes":[{}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],"buffers":[{{"byteLength":36}}],
        "bufferViews":[{{"buffer":0,"byteLength":36}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}}]}}"#,
        nodes.join(",")
    );
    std::fs::write(d.join("dag.glb"), render::mesh::glb_container(&json, &bin)).unwrap();
    let scene = scene_with(&d, "[[meshes]]\nfile = \"dag.glb\"\nmaterial = \"m\"\n");
    let out = d.join("out").display().to_string();
    assert_clean_error(
        &["render", "--scene", &scene, "--out", &out, "--quiet"],
        "reached twice",
    );
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn exr_declaring_100000_by_100000_is_refused_within_2_gib() {
    let d = dir("exr");
    let mut bytes = common::grey_exr_2x2();
    let key = b"dataWindow\0box2i\0";
    let at = bytes.windows(key.len()).position(|w| w == key).unwrap() + key.len() + 4;
    bytes[at + 8..at + 12].copy_from_slice(&99_999i32.to_le_bytes());
    bytes[at + 12..at + 16].copy_from_slice(&99_999i32.to_le_bytes());
    std::fs::write(d.join("sky.exr"), &bytes).unwrap();
    let scene = scene_with(
        &d,
        "[[meshes]]\nshape = \"sphere\"\nmaterial = \"m\"\nscale = 50\n[environment]\nexr = \"sky.exr\"\nintensity = 1\n",
    );
    let out = d.join("out").display().to_string();
    assert_clean_error(
        &["render", "--scene", &scene, "--out", &out, "--quiet"],
        "100000×100000",
    );
    std::fs::remove_dir_all(&d).unwrap();
}
