//! glTF 2.0 through the gltf crate (no image decoding): `.gltf` with external or base64 data-URI
//! buffers, and `.glb`. All triangle primitives (lists, strips, fans) of the meshes reachable from
//! the default scene (or the first scene; all meshes when there is none) are merged, with each
//! node's world transform applied. Primitives keep their own vertices (no welding across them).
//! Points and lines are skipped.
//!
//! Accessors are checked before reading (type, element count against the buffer view) so that a
//! malformed file gives an error rather than a panic inside the reader.

use std::path::Path;

use base64::Engine;
use glam::{Mat4, Vec3};
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::Mode;

use super::{ParseResult, Parsed};
use crate::error::MeshFault;

/// Deepest node hierarchy followed (guards against cyclic node graphs).
const MAX_DEPTH: usize = 256;

/// Parses glTF or GLB bytes; `dir` resolves relative buffer URIs.
///
/// The gltf crate (1.4.1) panics on some malformed documents during its own validation (an
/// index into an array the file does not have: found by the corrupted-input test), so a panic
/// inside it becomes this file's error instead of taking the process down.
pub(super) fn parse(bytes: &[u8], dir: &Path) -> ParseResult {
    std::panic::catch_unwind(|| parse_document(bytes, dir)).unwrap_or_else(|_| {
        Err("malformed glTF: a reference points outside its array (the gltf crate's validation \
             failed)"
            .into())
    })
}

fn parse_document(bytes: &[u8], dir: &Path) -> ParseResult {
    let gltf = gltf::Gltf::from_slice(bytes).map_err(|e| e.to_string())?;
    let buffers = load_buffers(&gltf, dir)?;
    let doc = &gltf.document;
    let mut out = Parsed {
        positions: Vec::new(),
        triangles: Vec::new(),
        file_vertices: 0,
        file_faces: 0,
        polygon_faces: 0,
    };
    match doc.default_scene().or_else(|| doc.scenes().next()) {
        Some(scene) => {
            let mut stack: Vec<(gltf::Node, Mat4, usize)> =
                scene.nodes().map(|n| (n, Mat4::IDENTITY, 0)).collect();
            while let Some((node, parent, depth)) = stack.pop() {
                if depth > MAX_DEPTH {
                    return Err(format!("node hierarchy deeper than {MAX_DEPTH} (a cycle?)"));
                }
                let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
                if let Some(mesh) = node.mesh()
                    && let Err(fault) = add_mesh(&mesh, world, &buffers, &mut out)?
                {
                    return Ok(Err(fault));
                }
                stack.extend(node.children().map(|c| (c, world, depth + 1)));
            }
        }
        None => {
            for mesh in doc.meshes() {
                if let Err(fault) = add_mesh(&mesh, Mat4::IDENTITY, &buffers, &mut out)? {
                    return Ok(Err(fault));
                }
            }
        }
    }
    Ok(Ok(out))
}

/// The bytes of every buffer, in document order.
fn load_buffers(gltf: &gltf::Gltf, dir: &Path) -> Result<Vec<Vec<u8>>, String> {
    let mut buffers = Vec::new();
    for buffer in gltf.document.buffers() {
        let data = match buffer.source() {
            gltf::buffer::Source::Bin => {
                gltf.blob.clone().ok_or("buffer refers to a missing GLB binary chunk")?
            }
            gltf::buffer::Source::Uri(uri) => {
                if let Some(rest) = uri.strip_prefix("data:") {
                    let (_, b64) = rest
                        .split_once(";base64,")
                        .ok_or("data URI buffer is not base64-encoded")?;
                    base64::engine::general_purpose::STANDARD
                        .decode(b64)
                        .map_err(|e| format!("data URI buffer: {e}"))?
                } else {
                    check_relative_uri(uri)?;
                    let file = dir.join(uri);
                    std::fs::read(&file)
                        .map_err(|e| format!("buffer file {}: {e}", file.display()))?
                }
            }
        };
        if data.len() < buffer.length() {
            return Err(format!(
                "buffer {} has {} bytes, declared {}",
                buffer.index(),
                data.len(),
                buffer.length()
            ));
        }
        buffers.push(data);
    }
    Ok(buffers)
}

/// A buffer URI must name a file in the asset's folder or below it: no absolute path, no
/// scheme other than `data:`, no `..` (a downloaded asset cannot make us read elsewhere).
fn check_relative_uri(uri: &str) -> Result<(), String> {
    let path = Path::new(uri);
    let escapes = path.is_absolute()
        || uri.starts_with('/')
        || uri.starts_with('\\')
        || uri.contains(':')
        || path
            .components()
            .any(|c| !matches!(c, std::path::Component::Normal(_) | std::path::Component::CurDir))
        || uri.split(['/', '\\']).any(|part| part == "..");
    if escapes {
        return Err(format!(
            "buffer URI {uri:?} points outside the asset's folder (absolute, a scheme or ..); \
             only relative paths below it and data: URIs are read"
        ));
    }
    Ok(())
}

/// Checks that an accessor is backed by a buffer view large enough for its elements.
fn check_accessor(a: &gltf::Accessor, what: &str) -> Result<(), String> {
    let view =
        a.view().ok_or_else(|| format!("{what} accessor {} has no buffer view", a.index()))?;
    let stride = view.stride().unwrap_or(a.size()).max(a.size());
    let needed = (a.count() as u128).saturating_sub(1) * stride as u128
        + a.size() as u128
        + a.offset() as u128;
    if a.count() == 0 || a.sparse().is_some() || needed > view.length() as u128 {
        return Err(format!(
            "{what} accessor {} is empty, sparse or exceeds its buffer view",
            a.index()
        ));
    }
    Ok(())
}

/// Appends the triangle primitives of one mesh transformed by `world`.
fn add_mesh(
    mesh: &gltf::Mesh,
    world: Mat4,
    buffers: &[Vec<u8>],
    out: &mut Parsed,
) -> Result<Result<(), MeshFault>, String> {
    let flip = world.determinant() < 0.0;
    for prim in mesh.primitives() {
        if !matches!(prim.mode(), Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan) {
            continue;
        }
        let pos = prim.get(&gltf::Semantic::Positions).ok_or("primitive without POSITION")?;
        if pos.dimensions() != Dimensions::Vec3 || pos.data_type() != DataType::F32 {
            return Err(format!("POSITION accessor {} is not float VEC3", pos.index()));
        }
        check_accessor(&pos, "POSITION")?;
        let reader = prim.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
        let local: Vec<Vec3> = reader
            .read_positions()
            .ok_or("POSITION accessor exceeds its buffer")?
            .map(|p| world.transform_point3(Vec3::from_array(p)))
            .collect();
        let indices: Vec<u32> = match prim.indices() {
            Some(acc) => {
                let ok_type =
                    matches!(acc.data_type(), DataType::U8 | DataType::U16 | DataType::U32);
                if !ok_type || acc.dimensions() != Dimensions::Scalar {
                    return Err(format!(
                        "index accessor {} is not an unsigned scalar",
                        acc.index()
                    ));
                }
                check_accessor(&acc, "index")?;
                reader
                    .read_indices()
                    .ok_or("index accessor exceeds its buffer")?
                    .into_u32()
                    .collect()
            }
            None => (0..local.len() as u32).collect(),
        };
        let tris: Vec<[u32; 3]> = match prim.mode() {
            Mode::Triangles => indices.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
            Mode::TriangleStrip => (0..indices.len().saturating_sub(2))
                .map(|i| {
                    let (a, b, c) = (indices[i], indices[i + 1], indices[i + 2]);
                    if i % 2 == 0 { [a, b, c] } else { [b, a, c] }
                })
                .collect(),
            _ => (1..indices.len().saturating_sub(1))
                .map(|i| [indices[0], indices[i], indices[i + 1]])
                .collect(),
        };
        let offset = out.positions.len();
        for (face, tri) in tris.iter().enumerate() {
            if let Some(&bad) = tri.iter().find(|&&i| i as usize >= local.len()) {
                return Ok(Err(MeshFault::IndexOutOfRange {
                    face: out.file_faces + face,
                    index: i64::from(bad),
                    vertex_count: local.len(),
                }));
            }
            let t = tri.map(|i| (i as usize + offset) as u32);
            out.triangles.push(if flip { [t[0], t[2], t[1]] } else { t });
        }
        out.file_faces += tris.len();
        out.file_vertices += local.len();
        out.positions.extend(local);
    }
    Ok(Ok(()))
}
