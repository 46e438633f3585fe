//! Hostile glTF binaries and OBJ files: each is refused with a message, never loops or panics.

use super::*;

/// Three vertices of the unit right triangle (f32 xyz) and the u16 indices `idx`.
fn triangle_bin(idx: [u16; 3]) -> Vec<u8> {
    let mut bin = Vec::new();
    for v in [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
        for c in v {
            bin.extend_from_slice(&c.to_le_bytes());
        }
    }
    for i in idx {
        bin.extend_from_slice(&i.to_le_bytes());
    }
    bin
}

/// A GLB whose one triangle mesh is referenced by `nodes` (JSON array text), scene roots `roots`,
/// the index accessor declaring `index_count` indices.
fn glb(nodes: &str, roots: &str, idx: [u16; 3], index_count: usize) -> Vec<u8> {
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":{roots}}}],"nodes":{nodes},
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],
        "buffers":[{{"byteLength":42}}],
        "bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":6}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}},
                     {{"bufferView":1,"componentType":5123,"count":{index_count},"type":"SCALAR"}}]}}"#
    );
    glb_container(&json, &triangle_bin(idx))
}

fn load(bytes: &[u8]) -> Result<TriangleMesh, String> {
    TriangleMesh::from_glb(bytes, Path::new("t.glb")).map_err(|e| e.to_string())
}

#[test]
fn glb_built_here_loads() {
    let m = load(&glb(r#"[{"mesh":0}]"#, "[0]", [0, 1, 2], 3)).unwrap();
    assert_eq!(m.triangle_count(), 1);
    // Normals were computed from the face: +Z.
    assert!(m.normals.iter().all(|n| (n.z - 1.0).abs() < 1e-6));
}

#[test]
fn glb_node_that_is_its_own_child_is_refused() {
    let e = load(&glb(r#"[{"mesh":0,"children":[0]}]"#, "[0]", [0, 1, 2], 3)).unwrap_err();
    assert!(e.contains("node 0 is reached twice"), "{e}");
}

#[test]
fn glb_node_dag_with_2_pow_40_paths_is_refused() {
    // Two nodes per level, each parent of both nodes of the next level: 2⁴⁰ root-to-leaf paths.
    let levels = 40;
    let nodes: Vec<String> = (0..2 * levels)
        .map(|i| {
            let next = 2 * (i / 2 + 1);
            if next < 2 * levels {
                format!(r#"{{"mesh":0,"children":[{next},{}]}}"#, next + 1)
            } else {
                r#"{"mesh":0}"#.to_string()
            }
        })
        .collect();
    let e = load(&glb(
        &format!("[{}]", nodes.join(",")),
        "[0,1]",
        [0, 1, 2],
        3,
    ))
    .unwrap_err();
    assert!(e.contains("reached twice"), "{e}");
}

#[test]
fn glb_node_chain_deeper_than_the_cap_is_refused() {
    let n = MAX_NODE_DEPTH + 1;
    let nodes: Vec<String> = (0..n)
        .map(|i| {
            if i + 1 < n {
                format!(r#"{{"children":[{}]}}"#, i + 1)
            } else {
                r#"{"mesh":0}"#.to_string()
            }
        })
        .collect();
    let e = load(&glb(&format!("[{}]", nodes.join(",")), "[0]", [0, 1, 2], 3)).unwrap_err();
    assert!(e.contains(&format!("deeper than {MAX_NODE_DEPTH}")), "{e}");
}

#[test]
fn glb_without_normals_and_an_out_of_range_index_is_refused() {
    let e = load(&glb(r#"[{"mesh":0}]"#, "[0]", [0, 1, 7], 3)).unwrap_err();
    assert!(e.contains("indexes past 3 vertices"), "{e}");
}

#[test]
fn glb_declaring_more_indices_than_the_triangle_cap_is_refused_before_reading() {
    let e = load(&glb(
        r#"[{"mesh":0}]"#,
        "[0]",
        [0, 1, 2],
        3 * (MAX_TRIANGLES + 1),
    ))
    .unwrap_err();
    assert!(e.contains(&format!("more than the {MAX_TRIANGLES}")), "{e}");
}

#[test]
fn glb_triangle_cap_is_named_in_the_error() {
    let e = check_caps(3, MAX_TRIANGLES + 1, Path::new("t.glb"))
        .unwrap_err()
        .to_string();
    assert!(e.contains(&MAX_TRIANGLES.to_string()), "{e}");
    let e = check_caps(MAX_VERTICES + 1, 1, Path::new("t.glb"))
        .unwrap_err()
        .to_string();
    assert!(e.contains(&MAX_VERTICES.to_string()), "{e}");
}

#[test]
fn obj_without_normals_and_an_out_of_range_index_is_refused() {
    let obj = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n";
    let r = TriangleMesh::from_obj(obj, Path::new("t.obj"));
    assert!(r.is_err(), "{r:?}");
}

#[test]
fn obj_with_non_finite_texture_coordinates_is_refused() {
    let obj = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt nan 0\nvt 0 1\nf 1/1 2/2 3/3\n";
    let r = TriangleMesh::from_obj(obj, Path::new("t.obj"));
    assert!(r.is_err(), "{r:?}");
}

#[test]
fn glb_with_float_indices_is_refused() {
    // componentType 5126 (f32) for indices reached an `unreachable!()` in the gltf reader.
    let bytes = glb(r#"[{"mesh":0}]"#, "[0]", [0, 1, 2], 3);
    let json_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let json = std::str::from_utf8(&bytes[20..20 + json_len]).unwrap();
    let bin_start = 20 + json_len + 8;
    let patched = json.replace(r#""componentType":5123"#, r#""componentType":5126"#);
    let e = load(&glb_container(
        patched.trim_end(),
        &bytes[bin_start..bin_start + 42],
    ))
    .unwrap_err();
    assert!(e.contains("indices are unsigned scalars"), "{e}");
}
