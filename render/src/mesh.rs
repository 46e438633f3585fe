//! Triangle meshes: glTF 2.0 binary (`gltf`, from bytes) and Wavefront OBJ (`tobj`) loaders,
//! procedural spheres and quads, and the placement transform that turns model units into mm.
//!
//! Millimetres are introduced in exactly one place: [`Placement::to_affine`] multiplies the model
//! coordinates by `units_mm` (mm per model unit) before rotating and translating them.

use crate::error::RenderError;
use glam::{Affine3A, Mat3A, Quat, Vec2, Vec3, Vec3A};
use std::path::Path;

/// Most triangles one mesh file may hold (about 0.5 GB once the BVH is built).
pub const MAX_TRIANGLES: usize = 4_000_000;
/// Most vertices one mesh file may hold.
pub const MAX_VERTICES: usize = 4_000_000;
/// Deepest glTF node hierarchy accepted (parent → child steps from a scene root).
pub const MAX_NODE_DEPTH: usize = 64;

/// An indexed triangle mesh with per-vertex shading normals and optional texture coordinates.
#[derive(Debug, Clone, PartialEq)]
pub struct TriangleMesh {
    /// Vertex positions (model units before placement, mm after).
    pub positions: Vec<Vec3>,
    /// Unit shading normals, one per vertex.
    pub normals: Vec<Vec3>,
    /// Texture coordinates (u, v), one per vertex, if the file has them.
    pub uvs: Option<Vec<Vec2>>,
    /// Triangles as vertex indices.
    pub indices: Vec<[u32; 3]>,
}

/// Where a mesh goes in the scene: model units → mm, then scale, rotation (degrees about X, then Y,
/// then Z) and translation (mm).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Placement {
    /// Millimetres per model unit.
    pub units_mm: f32,
    /// Extra uniform scale (dimensionless).
    pub scale: f32,
    /// Rotation about X, Y and Z, degrees, applied in that order.
    pub rotate_deg: Vec3,
    /// Translation, mm.
    pub translate_mm: Vec3,
}

impl Default for Placement {
    fn default() -> Self {
        Self {
            units_mm: 1.0,
            scale: 1.0,
            rotate_deg: Vec3::ZERO,
            translate_mm: Vec3::ZERO,
        }
    }
}

impl Placement {
    /// The affine map from model coordinates to scene millimetres (the one unit conversion).
    #[must_use]
    pub fn to_affine(&self) -> Affine3A {
        let r = self.rotate_deg * (std::f32::consts::PI / 180.0);
        let rot =
            Quat::from_rotation_z(r.z) * Quat::from_rotation_y(r.y) * Quat::from_rotation_x(r.x);
        Affine3A::from_scale_rotation_translation(
            Vec3::splat(self.units_mm * self.scale),
            rot,
            self.translate_mm,
        )
    }
}

impl TriangleMesh {
    /// Number of triangles.
    #[must_use]
    pub fn triangle_count(&self) -> usize {
        self.indices.len()
    }

    /// Apply an affine map to positions and (by the inverse transpose) to normals.
    pub fn transform(&mut self, m: &Affine3A) {
        let normal_m: Mat3A = m.matrix3.inverse().transpose();
        for p in &mut self.positions {
            *p = m.transform_point3(*p);
        }
        for n in &mut self.normals {
            *n = Vec3::from(normal_m * Vec3A::from(*n)).normalize_or_zero();
        }
    }

    /// Axis-aligned bounds (min, max).
    #[must_use]
    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.positions.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), &p| (lo.min(p), hi.max(p)),
        )
    }

    /// Check the size caps, that indices are in range and every value finite.
    fn validate(self, path: &Path) -> Result<Self, RenderError> {
        let err = |message: String| RenderError::Mesh {
            path: path.to_path_buf(),
            message,
        };
        if self.indices.is_empty() {
            return Err(err("no triangles".into()));
        }
        check_caps(self.positions.len(), self.indices.len(), path)?;
        let n = self.positions.len() as u32;
        if let Some(t) = self.indices.iter().find(|t| t.iter().any(|&i| i >= n)) {
            return Err(err(format!("triangle {t:?} indexes past {n} vertices")));
        }
        if self.positions.iter().any(|p| !p.is_finite()) {
            return Err(err("non-finite vertex position".into()));
        }
        if self.uvs.iter().flatten().any(|uv| !uv.is_finite()) {
            return Err(err("non-finite texture coordinate".into()));
        }
        if let Some(uvs) = &self.uvs
            && uvs.len() != self.positions.len()
        {
            return Err(err(
                "texture coordinate count differs from vertex count".into()
            ));
        }
        Ok(self)
    }

    /// Fill missing or degenerate normals with area-weighted face normals.
    fn with_normals(mut self) -> Self {
        if self.normals.len() == self.positions.len()
            && self
                .normals
                .iter()
                .all(|n| n.is_finite() && n.length_squared() > 0.5)
        {
            return self;
        }
        let mut acc = vec![Vec3::ZERO; self.positions.len()];
        for t in &self.indices {
            let [a, b, c] = t.map(|i| self.positions[i as usize]);
            let n = (b - a).cross(c - a); // length = 2 × area: area weighting
            for &i in t {
                acc[i as usize] += n;
            }
        }
        self.normals = acc.into_iter().map(|n| n.normalize_or(Vec3::Z)).collect();
        self
    }

    /// Load a glTF 2.0 binary (`.glb`) from bytes: every triangle primitive of every node of the
    /// default scene, with node transforms applied (model units).
    pub fn from_glb(bytes: &[u8], path: &Path) -> Result<Self, RenderError> {
        let err = |message: String| RenderError::Mesh {
            path: path.to_path_buf(),
            message,
        };
        let gltf = gltf::Gltf::from_slice(bytes).map_err(|e| err(e.to_string()))?;
        let blob = gltf.blob.as_deref();
        let mut mesh = TriangleMesh {
            positions: Vec::new(),
            normals: Vec::new(),
            uvs: Some(Vec::new()),
            indices: Vec::new(),
        };
        let scene = gltf
            .default_scene()
            .or_else(|| gltf.scenes().next())
            .ok_or_else(|| err("no scene".into()))?;
        // glTF nodes form trees (a node has at most one parent): each node is visited once, so a
        // node that is its own ancestor or is shared by two parents is refused, not re-entered.
        let mut visited = vec![false; gltf.nodes().len()];
        let mut stack: Vec<(gltf::Node, glam::Mat4, usize)> = scene
            .nodes()
            .map(|n| (n, glam::Mat4::IDENTITY, 1))
            .collect();
        while let Some((node, parent, depth)) = stack.pop() {
            if std::mem::replace(&mut visited[node.index()], true) {
                return Err(err(format!(
                    "node {} is reached twice (a node hierarchy must be a tree: no cycles, one parent per node)",
                    node.index()
                )));
            }
            if depth > MAX_NODE_DEPTH {
                return Err(err(format!(
                    "node hierarchy deeper than {MAX_NODE_DEPTH} levels"
                )));
            }
            let world = parent * glam::Mat4::from_cols_array_2d(&node.transform().matrix());
            if let Some(m) = node.mesh() {
                for prim in m.primitives() {
                    if prim.mode() != gltf::mesh::Mode::Triangles {
                        continue;
                    }
                    check_accessor_types(&prim, path)?;
                    // Counts declared by the accessors, checked before anything is read.
                    let vertices = prim
                        .get(&gltf::Semantic::Positions)
                        .map_or(0, |a| a.count());
                    let corners = prim.indices().map_or(vertices, |a| a.count());
                    check_caps(
                        mesh.positions.len().saturating_add(vertices),
                        mesh.indices.len().saturating_add(corners / 3),
                        path,
                    )?;
                    let reader = prim.reader(|b| match b.source() {
                        gltf::buffer::Source::Bin => blob,
                        gltf::buffer::Source::Uri(_) => None,
                    });
                    let base = mesh.positions.len() as u32;
                    let pos: Vec<Vec3> = reader
                        .read_positions()
                        .ok_or_else(|| err("primitive without POSITION".into()))?
                        .map(|p| world.transform_point3(Vec3::from(p)))
                        .collect();
                    let count = pos.len();
                    let normal_m = glam::Mat3::from_mat4(world).inverse().transpose();
                    let normals: Vec<Vec3> = match reader.read_normals() {
                        Some(it) => it
                            .map(|n| (normal_m * Vec3::from(n)).normalize_or_zero())
                            .collect(),
                        None => vec![Vec3::ZERO; count],
                    };
                    match (reader.read_tex_coords(0), &mut mesh.uvs) {
                        (Some(tc), Some(uvs)) => uvs.extend(tc.into_f32().map(Vec2::from)),
                        _ => mesh.uvs = None,
                    }
                    let idx: Vec<u32> = match reader.read_indices() {
                        Some(i) => i.into_u32().collect(),
                        None => (0..count as u32).collect(),
                    };
                    mesh.positions.extend(pos);
                    mesh.normals.extend(normals);
                    mesh.indices.extend(
                        idx.chunks_exact(3)
                            .map(|c| [c[0] + base, c[1] + base, c[2] + base]),
                    );
                }
            }
            stack.extend(node.children().map(|c| (c, world, depth + 1)));
        }
        Ok(mesh.validate(path)?.with_normals())
    }

    /// Load a Wavefront OBJ from bytes (triangulated; materials ignored: the scene assigns them).
    pub fn from_obj(bytes: &[u8], path: &Path) -> Result<Self, RenderError> {
        let err = |message: String| RenderError::Mesh {
            path: path.to_path_buf(),
            message,
        };
        let mut reader = std::io::BufReader::new(bytes);
        let (models, _) = tobj::load_obj_buf(&mut reader, &tobj::GPU_LOAD_OPTIONS, |_| {
            Err(tobj::LoadError::OpenFileFailed)
        })
        .map_err(|e| err(e.to_string()))?;
        let mut mesh = TriangleMesh {
            positions: Vec::new(),
            normals: Vec::new(),
            uvs: Some(Vec::new()),
            indices: Vec::new(),
        };
        for m in models {
            let m = m.mesh;
            check_caps(
                mesh.positions.len() + m.positions.len() / 3,
                mesh.indices.len() + m.indices.len() / 3,
                path,
            )?;
            let base = mesh.positions.len() as u32;
            let count = m.positions.len() / 3;
            mesh.positions.extend(
                m.positions
                    .chunks_exact(3)
                    .map(|p| Vec3::new(p[0], p[1], p[2])),
            );
            if m.normals.len() == 3 * count {
                mesh.normals.extend(
                    m.normals
                        .chunks_exact(3)
                        .map(|n| Vec3::new(n[0], n[1], n[2]).normalize_or_zero()),
                );
            } else {
                mesh.normals.extend(std::iter::repeat_n(Vec3::ZERO, count));
            }
            match &mut mesh.uvs {
                Some(uvs) if m.texcoords.len() == 2 * count => {
                    uvs.extend(m.texcoords.chunks_exact(2).map(|t| Vec2::new(t[0], t[1])));
                }
                _ => mesh.uvs = None,
            }
            mesh.indices.extend(
                m.indices
                    .chunks_exact(3)
                    .map(|c| [c[0] + base, c[1] + base, c[2] + base]),
            );
        }
        Ok(mesh.validate(path)?.with_normals())
    }

    /// A unit sphere (radius 1, centred at the origin) from a subdivided icosahedron with
    /// 20 · 4^`subdivisions` triangles; normals are the exact sphere normals.
    #[must_use]
    pub fn sphere(subdivisions: u32) -> Self {
        let t = (1.0 + 5f32.sqrt()) / 2.0;
        let mut positions: Vec<Vec3> = [
            (-1.0, t, 0.0),
            (1.0, t, 0.0),
            (-1.0, -t, 0.0),
            (1.0, -t, 0.0),
            (0.0, -1.0, t),
            (0.0, 1.0, t),
            (0.0, -1.0, -t),
            (0.0, 1.0, -t),
            (t, 0.0, -1.0),
            (t, 0.0, 1.0),
            (-t, 0.0, -1.0),
            (-t, 0.0, 1.0),
        ]
        .iter()
        .map(|&(x, y, z)| Vec3::new(x, y, z).normalize())
        .collect();
        let mut indices: Vec<[u32; 3]> = vec![
            [0, 11, 5],
            [0, 5, 1],
            [0, 1, 7],
            [0, 7, 10],
            [0, 10, 11],
            [1, 5, 9],
            [5, 11, 4],
            [11, 10, 2],
            [10, 7, 6],
            [7, 1, 8],
            [3, 9, 4],
            [3, 4, 2],
            [3, 2, 6],
            [3, 6, 8],
            [3, 8, 9],
            [4, 9, 5],
            [2, 4, 11],
            [6, 2, 10],
            [8, 6, 7],
            [9, 8, 1],
        ];
        for _ in 0..subdivisions {
            let mut mid = std::collections::HashMap::new();
            let mut midpoint = |a: u32, b: u32, positions: &mut Vec<Vec3>| -> u32 {
                *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                    positions.push((positions[a as usize] + positions[b as usize]).normalize());
                    positions.len() as u32 - 1
                })
            };
            let mut next = Vec::with_capacity(indices.len() * 4);
            for [a, b, c] in indices {
                let ab = midpoint(a, b, &mut positions);
                let bc = midpoint(b, c, &mut positions);
                let ca = midpoint(c, a, &mut positions);
                next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
            }
            indices = next;
        }
        let uvs = positions
            .iter()
            .map(|p| {
                Vec2::new(
                    0.5 + p.z.atan2(p.x) / std::f32::consts::TAU,
                    p.y.clamp(-1.0, 1.0).acos() / std::f32::consts::PI,
                )
            })
            .collect();
        Self {
            normals: positions.clone(),
            positions,
            uvs: Some(uvs),
            indices,
        }
    }

    /// The square [−1, 1]² in the XY plane facing +Z (two triangles, UVs over [0, 1]²).
    #[must_use]
    pub fn quad() -> Self {
        Self {
            positions: vec![
                Vec3::new(-1.0, -1.0, 0.0),
                Vec3::new(1.0, -1.0, 0.0),
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::new(-1.0, 1.0, 0.0),
            ],
            normals: vec![Vec3::Z; 4],
            uvs: Some(vec![
                Vec2::new(0.0, 1.0),
                Vec2::new(1.0, 1.0),
                Vec2::new(1.0, 0.0),
                Vec2::new(0.0, 0.0),
            ]),
            indices: vec![[0, 1, 2], [0, 2, 3]],
        }
    }
}

/// Pack a glTF JSON document and its binary buffer into a GLB container (glTF 2.0 "GLB File
/// Format Specification": 12-byte header, then JSON and BIN chunks padded to 4 bytes).
#[must_use]
pub fn glb_container(json: &str, bin: &[u8]) -> Vec<u8> {
    let pad = |n: usize| n.div_ceil(4) * 4;
    let (json_len, bin_len) = (pad(json.len()), pad(bin.len()));
    let total = 12 + 8 + json_len + if bin.is_empty() { 0 } else { 8 + bin_len };
    let mut out = Vec::with_capacity(total);
    let word = |out: &mut Vec<u8>, v: usize| out.extend_from_slice(&(v as u32).to_le_bytes());
    out.extend_from_slice(b"glTF");
    word(&mut out, 2);
    word(&mut out, total);
    word(&mut out, json_len);
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(json.as_bytes());
    out.resize(20 + json_len, b' ');
    if !bin.is_empty() {
        word(&mut out, bin_len);
        out.extend_from_slice(b"BIN\0");
        out.extend_from_slice(bin);
        out.resize(total, 0);
    }
    out
}

/// Refuse accessors whose component type or shape the glTF spec does not allow for their
/// attribute (the `gltf` readers assume them and would panic otherwise).
fn check_accessor_types(prim: &gltf::Primitive, path: &Path) -> Result<(), RenderError> {
    use gltf::Semantic;
    use gltf::accessor::{DataType, Dimensions};
    let ok = |a: &gltf::Accessor, types: &[DataType], dims: Dimensions| {
        types.contains(&a.data_type()) && a.dimensions() == dims
    };
    for (semantic, a) in prim.attributes() {
        let fine = match semantic {
            Semantic::Positions | Semantic::Normals => ok(&a, &[DataType::F32], Dimensions::Vec3),
            Semantic::TexCoords(_) => ok(
                &a,
                &[DataType::F32, DataType::U8, DataType::U16],
                Dimensions::Vec2,
            ),
            _ => true,
        };
        if !fine {
            return Err(RenderError::Mesh {
                path: path.to_path_buf(),
                message: format!(
                    "accessor {} of {semantic:?} has type {:?} {:?}, which glTF does not allow there",
                    a.index(),
                    a.data_type(),
                    a.dimensions()
                ),
            });
        }
    }
    if let Some(a) = prim.indices()
        && !ok(
            &a,
            &[DataType::U8, DataType::U16, DataType::U32],
            Dimensions::Scalar,
        )
    {
        return Err(RenderError::Mesh {
            path: path.to_path_buf(),
            message: format!(
                "index accessor {} has type {:?} {:?}; indices are unsigned scalars",
                a.index(),
                a.data_type(),
                a.dimensions()
            ),
        });
    }
    Ok(())
}

/// Refuse more than [`MAX_VERTICES`] vertices or [`MAX_TRIANGLES`] triangles.
fn check_caps(vertices: usize, triangles: usize, path: &Path) -> Result<(), RenderError> {
    let err = |message: String| {
        Err(RenderError::Mesh {
            path: path.to_path_buf(),
            message,
        })
    };
    if vertices > MAX_VERTICES {
        return err(format!(
            "{vertices} vertices, more than the {MAX_VERTICES} a mesh may have"
        ));
    }
    if triangles > MAX_TRIANGLES {
        return err(format!(
            "{triangles} triangles, more than the {MAX_TRIANGLES} a mesh may have"
        ));
    }
    Ok(())
}

#[cfg(test)]
mod glb_tests;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn head_glb_loads_with_uvs() {
        let bytes = include_bytes!("../assets/LeePerrySmith.glb");
        let m = TriangleMesh::from_glb(bytes, Path::new("LeePerrySmith.glb")).unwrap();
        assert_eq!(m.triangle_count(), 17_684);
        assert!(m.uvs.is_some());
    }

    #[test]
    fn obj_loads_and_fills_normals() {
        let obj = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n";
        let m = TriangleMesh::from_obj(obj, Path::new("q.obj")).unwrap();
        assert_eq!(m.triangle_count(), 2);
        assert!(m.normals.iter().all(|n| (n.z - 1.0).abs() < 1e-6));
    }

    #[test]
    fn placement_scales_model_units_to_mm() {
        let p = Placement {
            units_mm: 45.0,
            scale: 2.0,
            rotate_deg: Vec3::new(0.0, 90.0, 0.0),
            translate_mm: Vec3::new(10.0, 0.0, 0.0),
        };
        let q = p.to_affine().transform_point3(Vec3::X);
        assert!((q - Vec3::new(10.0, 0.0, -90.0)).length() < 1e-3, "{q}");
    }

    #[test]
    fn sphere_has_expected_triangles() {
        assert_eq!(TriangleMesh::sphere(2).triangle_count(), 320);
    }
}
