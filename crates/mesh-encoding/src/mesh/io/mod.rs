//! Loading OBJ, PLY and glTF/GLB files into one [`TriMesh`], chosen by file extension.
//!
//! Every loader returns the triangulated, validated mesh plus what it saw in the file; polygons
//! are split into fans around their first corner (exact for convex polygons such as the quads of
//! the test meshes). [`load_mesh`] then cleans the mesh up and optionally normalises it.
//! Failures are [`Error`]s naming the file; no input makes a loader panic.

mod gltf;
mod obj;
mod ply;

use std::fmt;
use std::path::{Path, PathBuf};

use super::{CleanupReport, Similarity, Topology, TriMesh};
use crate::error::{Error, MeshFault, Result};

/// The file formats [`load_mesh`] reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum MeshFormat {
    /// Wavefront OBJ (`.obj`), read with tobj; groups and objects are merged into one mesh.
    Obj,
    /// Stanford PLY (`.ply`), ASCII or binary (little or big endian).
    Ply,
    /// glTF 2.0, JSON with external or data-URI buffers (`.gltf`) or binary (`.glb`); node
    /// transforms of the default scene are applied.
    Gltf,
}

impl MeshFormat {
    /// The format for a path's extension (case-insensitive).
    pub fn from_path(path: &Path) -> Result<Self> {
        let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
        match ext.as_str() {
            "obj" => Ok(MeshFormat::Obj),
            "ply" => Ok(MeshFormat::Ply),
            "gltf" | "glb" => Ok(MeshFormat::Gltf),
            _ => Err(Error::UnsupportedFormat { path: path.to_owned(), extension: ext }),
        }
    }
}

impl fmt::Display for MeshFormat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            MeshFormat::Obj => "OBJ",
            MeshFormat::Ply => "PLY",
            MeshFormat::Gltf => "glTF",
        })
    }
}

/// Options of [`load_mesh`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LoadOptions {
    /// Run [`TriMesh::cleanup`] (default true).
    pub cleanup: bool,
    /// Normalise into the unit sphere with [`TriMesh::normalize_unit_sphere`] (default false).
    pub normalize_unit_sphere: bool,
}

impl Default for LoadOptions {
    fn default() -> Self {
        LoadOptions { cleanup: true, normalize_unit_sphere: false }
    }
}

/// What [`load_mesh`] found and did.
#[derive(Debug, Clone, PartialEq)]
pub struct LoadReport {
    /// The file.
    pub path: PathBuf,
    /// Its format.
    pub format: MeshFormat,
    /// Vertices declared in the file.
    pub file_vertices: usize,
    /// Faces in the file (before triangulation; points and lines are not counted).
    pub file_faces: usize,
    /// Faces with more than three corners, split into triangles.
    pub polygon_faces: usize,
    /// What cleanup removed (all zero when cleanup was off, except vertices the loader skipped).
    pub cleanup: CleanupReport,
    /// Topology of the final mesh.
    pub topology: Topology,
}

/// A loaded mesh with its report.
#[derive(Debug, Clone)]
pub struct LoadedMesh {
    /// The final mesh.
    pub mesh: TriMesh,
    /// What was found and done.
    pub report: LoadReport,
    /// The normalisation applied, if requested.
    pub normalization: Option<Similarity>,
}

/// What a format loader hands back: the triangulated mesh (not yet validated) and file counts.
#[derive(Debug)]
struct Parsed {
    positions: Vec<glam::Vec3>,
    triangles: Vec<[u32; 3]>,
    file_vertices: usize,
    file_faces: usize,
    polygon_faces: usize,
}

/// Loads, validates, cleans up (unless disabled) and optionally normalises a mesh file.
///
/// # Errors
/// [`Error::Io`] when the file cannot be read, [`Error::UnsupportedFormat`] for an unknown
/// extension, [`Error::Parse`] for a malformed file and [`Error::Invalid`] for non-finite
/// coordinates, out-of-range indices or an empty mesh (also when cleanup leaves nothing).
pub fn load_mesh(path: impl AsRef<Path>, options: &LoadOptions) -> Result<LoadedMesh> {
    let path = path.as_ref();
    let format = MeshFormat::from_path(path)?;
    let bytes = std::fs::read(path).map_err(|source| Error::Io { path: path.into(), source })?;
    let parse_err = |message: String| Error::Parse { path: path.into(), format, message };
    let parsed = match format {
        MeshFormat::Obj => obj::parse(&bytes).map_err(parse_err)?,
        MeshFormat::Ply => ply::parse(&bytes).map_err(parse_err)?,
        MeshFormat::Gltf => {
            let dir = path.parent().unwrap_or(Path::new("."));
            gltf::parse(&bytes, dir).map_err(parse_err)?
        }
    }
    .map_err(|fault| Error::Invalid { path: path.into(), fault })?;
    let invalid = |fault| Error::Invalid { path: path.into(), fault };
    let mut mesh = TriMesh { positions: parsed.positions, triangles: parsed.triangles };
    mesh.validate().map_err(invalid)?;
    let skipped_by_loader = parsed.file_vertices.saturating_sub(mesh.positions.len());
    let mut cleanup = if options.cleanup { mesh.cleanup() } else { CleanupReport::default() };
    cleanup.unreferenced_vertices += skipped_by_loader;
    mesh.validate().map_err(invalid)?;
    let normalization = options.normalize_unit_sphere.then(|| mesh.normalize_unit_sphere());
    let report = LoadReport {
        path: path.into(),
        format,
        file_vertices: parsed.file_vertices,
        file_faces: parsed.file_faces,
        polygon_faces: parsed.polygon_faces,
        cleanup,
        topology: Topology::of(&mesh),
    };
    Ok(LoadedMesh { mesh, report, normalization })
}

/// Accumulates polygons as triangle fans, checking every index against the vertex count.
struct FanBuilder {
    vertex_count: usize,
    triangles: Vec<[u32; 3]>,
    faces: usize,
    polygons: usize,
}

impl FanBuilder {
    fn new(vertex_count: usize) -> Self {
        FanBuilder { vertex_count, triangles: Vec::new(), faces: 0, polygons: 0 }
    }

    /// Adds one face given by signed indices (PLY lists may hold negative numbers).
    fn push(&mut self, corners: impl ExactSizeIterator<Item = i64>) -> Result<(), MeshFault> {
        let face = self.faces;
        self.faces += 1;
        let n = corners.len();
        if n < 3 {
            return Err(MeshFault::TooFewCorners { face, corners: n });
        }
        if n > 3 {
            self.polygons += 1;
        }
        let mut first = 0;
        let mut prev = 0;
        for (k, index) in corners.enumerate() {
            if index < 0 || index as u64 >= self.vertex_count as u64 {
                return Err(MeshFault::IndexOutOfRange {
                    face,
                    index,
                    vertex_count: self.vertex_count,
                });
            }
            let i = index as u32;
            match k {
                0 => first = i,
                1 => {}
                _ => self.triangles.push([first, prev, i]),
            }
            prev = i;
        }
        Ok(())
    }
}

/// A loader result: outer error for a malformed file, inner for invalid mesh data.
type ParseResult = std::result::Result<std::result::Result<Parsed, MeshFault>, String>;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fans_and_range_checks() {
        let mut b = FanBuilder::new(5);
        b.push([0i64, 1, 2, 3, 4].into_iter()).unwrap();
        assert_eq!(b.triangles, vec![[0, 1, 2], [0, 2, 3], [0, 3, 4]]);
        assert_eq!((b.faces, b.polygons), (1, 1));
        assert!(matches!(
            b.push([0i64, 1, 5].into_iter()),
            Err(MeshFault::IndexOutOfRange { face: 1, index: 5, vertex_count: 5 })
        ));
        assert!(matches!(
            b.push([0i64, -1, 2].into_iter()),
            Err(MeshFault::IndexOutOfRange { index: -1, .. })
        ));
        assert!(matches!(
            b.push([0i64, 1].into_iter()),
            Err(MeshFault::TooFewCorners { corners: 2, .. })
        ));
    }

    #[test]
    fn format_from_extension() {
        assert_eq!(MeshFormat::from_path(Path::new("a/B.OBJ")).unwrap(), MeshFormat::Obj);
        assert_eq!(MeshFormat::from_path(Path::new("x.glb")).unwrap(), MeshFormat::Gltf);
        let e = MeshFormat::from_path(Path::new("dir/x.stl")).unwrap_err();
        assert!(e.to_string().contains("dir/x.stl") && e.to_string().contains("stl"), "{e}");
    }
}
