//! Binary little-endian PLY meshes for the renderer exports: positions, normals, optional
//! per-vertex float properties, triangles.
//!
//! Mitsuba 3's `ply` loader turns a vertex property group `<name>_0`, `<name>_1`, ... into the
//! mesh attribute `vertex_<name>` (the names its own `Mesh::write_ply` writes), which a
//! `mesh_attribute` texture then reads; pbrt-v4's `plymesh` ignores properties it does not know.

use super::gltf::ExportMesh;
use crate::Result;
use std::fmt::Write as _;
use std::path::Path;

/// A per-vertex attribute: `name` with `values.len() / vertices` components.
pub struct VertexAttribute<'a> {
    /// Mitsuba's attribute name without the `vertex_` prefix.
    pub name: &'a str,
    /// Components per vertex (1 or 3).
    pub components: usize,
    /// `[vertices, components]`.
    pub values: Vec<f32>,
}

/// Writes `path` atomically.
pub fn write(path: &Path, mesh: &ExportMesh<'_>, attributes: &[VertexAttribute<'_>]) -> Result<()> {
    let n = mesh.positions.len();
    let mut header = String::from("ply\nformat binary_little_endian 1.0\n");
    let _ = writeln!(header, "comment written by neural-brdf experiments export");
    let _ = writeln!(header, "element vertex {n}");
    for p in ["x", "y", "z", "nx", "ny", "nz"] {
        let _ = writeln!(header, "property float {p}");
    }
    for a in attributes {
        debug_assert_eq!(a.values.len(), n * a.components);
        for k in 0..a.components {
            let _ = writeln!(header, "property float {}_{k}", a.name);
        }
    }
    let _ = writeln!(header, "element face {}", mesh.triangles.len());
    header.push_str("property list uchar int vertex_indices\nend_header\n");
    let mut bytes = header.into_bytes();
    for i in 0..n {
        for x in mesh.positions[i].iter().chain(&mesh.normals[i]) {
            bytes.extend_from_slice(&x.to_le_bytes());
        }
        for a in attributes {
            for x in &a.values[i * a.components..(i + 1) * a.components] {
                bytes.extend_from_slice(&x.to_le_bytes());
            }
        }
    }
    for t in mesh.triangles {
        bytes.push(3);
        for &i in t {
            bytes.extend_from_slice(&(i as i32).to_le_bytes());
        }
    }
    stdx::fs::write_atomic(path, &bytes)?;
    Ok(())
}
