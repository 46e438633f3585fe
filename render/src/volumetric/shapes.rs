//! Closed test shapes for the volumetric reference, as Wavefront OBJ text (the scene loader reads
//! them like any mesh): boxes for slabs of a given thickness, and icospheres of a given
//! tessellation.

use crate::mesh::TriangleMesh;
use std::fmt::Write as _;

/// An icosphere of radius `radius_mm` centred on the origin (`TriangleMesh::sphere`:
/// 20 · 4^`subdivisions` triangles), with its exact sphere normals at the vertices, as OBJ.
#[must_use]
pub fn sphere_obj(subdivisions: u32, radius_mm: f32) -> String {
    let mesh = TriangleMesh::sphere(subdivisions);
    let mut obj = format!(
        "# icosphere, {subdivisions} subdivisions, {} triangles, radius {radius_mm} mm\n",
        mesh.indices.len()
    );
    for (p, n) in mesh.positions.iter().zip(&mesh.normals) {
        let p = *p * radius_mm;
        let _ = writeln!(obj, "v {} {} {}\nvn {} {} {}", p.x, p.y, p.z, n.x, n.y, n.z);
    }
    for t in &mesh.indices {
        let [a, b, c] = t.map(|i| i + 1);
        let _ = writeln!(obj, "f {a}//{a} {b}//{b} {c}//{c}");
    }
    obj
}

/// A closed box of `size_mm` = [x, y, z] centred on the origin, 12 outward-facing triangles, as OBJ.
#[must_use]
pub fn box_obj(size_mm: [f32; 3]) -> String {
    let h = size_mm.map(|s| 0.5 * s);
    let mut obj = String::from("# box\n");
    for i in 0..8 {
        let sign = |bit: usize| if i & bit == 0 { -1.0 } else { 1.0 };
        let _ = writeln!(
            obj,
            "v {} {} {}",
            sign(1) * h[0],
            sign(2) * h[1],
            sign(4) * h[2]
        );
    }
    // Corners are 1 + (x bit) + 2·(y bit) + 4·(z bit); each face counter-clockwise seen from outside.
    let faces = [
        [1, 3, 7, 5], // −x
        [2, 6, 8, 4], // +x
        [1, 5, 6, 2], // −y
        [3, 4, 8, 7], // +y
        [1, 2, 4, 3], // −z
        [5, 7, 8, 6], // +z
    ];
    // One normal per face: the shading normal is the face's (no smoothing across the edges).
    let normals = ["-1 0 0", "1 0 0", "0 -1 0", "0 1 0", "0 0 -1", "0 0 1"];
    for (k, ([a, b, c, d], n)) in faces.iter().zip(normals).enumerate() {
        let k = k + 1;
        let _ = writeln!(
            obj,
            "vn {n}\nf {a}//{k} {b}//{k} {c}//{k}\nf {a}//{k} {c}//{k} {d}//{k}"
        );
    }
    obj
}
