//! The scene's own copy of its mesh: binary little-endian PLY, which keeps vertex and triangle
//! order exactly (triangle ids in the precompute refer to it).

use crate::error::{Error, Result};
use mesh_encoding::TriMesh;
use std::path::Path;

/// The mesh as binary PLY bytes. The header's comment names dataset-merl, where the format was
/// born: it is part of every scene's bytes (so of every run id) and stays as it is.
pub fn ply_bytes(mesh: &TriMesh) -> Vec<u8> {
    let header = format!(
        "ply\nformat binary_little_endian 1.0\ncomment written by dataset-merl\n\
         element vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
         element face {}\nproperty list uchar int vertex_indices\nend_header\n",
        mesh.positions.len(),
        mesh.triangles.len()
    );
    let mut out = header.into_bytes();
    for p in &mesh.positions {
        for c in [p.x, p.y, p.z] {
            out.extend_from_slice(&c.to_le_bytes());
        }
    }
    for t in &mesh.triangles {
        out.push(3);
        for &i in t {
            out.extend_from_slice(&(i as i32).to_le_bytes());
        }
    }
    out
}

/// Loads a scene's mesh exactly as stored (no cleanup, no normalisation).
pub fn load(path: &Path) -> Result<TriMesh> {
    let options = mesh_encoding::LoadOptions { cleanup: false, normalize_unit_sphere: false };
    let loaded = mesh_encoding::load_mesh(path, &options)?;
    if loaded.mesh.triangles.is_empty() {
        return Err(Error::Dataset { path: path.into(), fault: "mesh has no triangles".into() });
    }
    Ok(loaded.mesh)
}
