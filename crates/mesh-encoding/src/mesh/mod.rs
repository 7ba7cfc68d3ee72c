//! The indexed triangle mesh ([`TriMesh`]) and everything done to it before ray casting: loading
//! ([`load_mesh`]), cleanup ([`TriMesh::cleanup`]), topology statistics ([`Topology`]), vertex
//! normals ([`TriMesh::vertex_normals`]) and normalisation into the unit sphere
//! ([`TriMesh::normalize_unit_sphere`]).
//!
//! Conventions: positions are f32 in the file's units (or unit-sphere units after normalising);
//! triangles are counter-clockwise seen from outside, as the file gives them (the loader does not
//! reorient faces); indices are `u32`.

mod cleanup;
mod io;
mod normalize;
mod normals;
mod shapes;
mod topology;

use glam::{DVec3, Vec3};

use crate::error::{Error, MeshFault, Result};

pub use cleanup::CleanupReport;
pub use io::{LoadOptions, LoadReport, LoadedMesh, MeshFormat, load_mesh};
pub use normalize::Similarity;
pub use normals::{NormalWeighting, interpolate_normal};
pub use shapes::icosphere;
pub use topology::Topology;

/// An indexed triangle mesh.
///
/// A `TriMesh` obtained from [`TriMesh::new`] or [`load_mesh`] is valid: non-empty, every
/// coordinate finite and every index in range. The fields are public for reading; code that edits
/// them should call [`TriMesh::validate`] afterwards.
#[derive(Debug, Clone, PartialEq)]
pub struct TriMesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Triangles as three vertex indices, counter-clockwise seen from the front.
    pub triangles: Vec<[u32; 3]>,
}

impl TriMesh {
    /// Builds a mesh and validates it.
    ///
    /// # Errors
    /// [`Error::Invalid`] (path `<memory>`) when the mesh is empty, has a non-finite coordinate or
    /// an index out of range.
    pub fn new(positions: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> Result<Self> {
        let mesh = TriMesh { positions, triangles };
        mesh.validate().map_err(Error::in_memory)?;
        Ok(mesh)
    }

    /// Checks the invariants: non-empty, finite coordinates, indices in range.
    pub fn validate(&self) -> std::result::Result<(), MeshFault> {
        if self.positions.is_empty() || self.triangles.is_empty() {
            return Err(MeshFault::Empty);
        }
        if u32::try_from(self.positions.len()).is_err() {
            return Err(MeshFault::TooManyVertices(self.positions.len()));
        }
        if let Some((vertex, p)) = self.positions.iter().enumerate().find(|(_, p)| !p.is_finite()) {
            return Err(MeshFault::NonFiniteVertex { vertex, position: p.to_array() });
        }
        let n = self.positions.len();
        for (face, tri) in self.triangles.iter().enumerate() {
            if let Some(&index) = tri.iter().find(|&&i| i as usize >= n) {
                return Err(MeshFault::IndexOutOfRange {
                    face,
                    index: i64::from(index),
                    vertex_count: n,
                });
            }
        }
        Ok(())
    }

    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// The three corner positions of triangle `t`.
    ///
    /// # Panics
    /// If `t` is out of range.
    pub fn corners(&self, t: usize) -> [Vec3; 3] {
        let [a, b, c] = self.triangles[t];
        [self.positions[a as usize], self.positions[b as usize], self.positions[c as usize]]
    }

    /// Twice the area vector of triangle `t` ((b - a) x (c - a)), computed in f64. Its direction
    /// is the geometric normal of a counter-clockwise triangle, its length twice the area.
    pub fn doubled_area_vector(&self, t: usize) -> DVec3 {
        let [a, b, c] = self.corners(t).map(|p| p.as_dvec3());
        (b - a).cross(c - a)
    }

    /// Total surface area.
    pub fn area(&self) -> f64 {
        (0..self.triangles.len()).map(|t| 0.5 * self.doubled_area_vector(t).length()).sum()
    }

    /// Axis-aligned bounding box `(min, max)` of the vertices.
    pub fn bounding_box(&self) -> (Vec3, Vec3) {
        self.positions
            .iter()
            .fold((Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)), |(lo, hi), p| {
                (lo.min(*p), hi.max(*p))
            })
    }

    /// Length of the bounding-box diagonal: the scene scale used for relative tolerances.
    pub fn diagonal(&self) -> f32 {
        let (lo, hi) = self.bounding_box();
        (hi - lo).length()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tetra() -> TriMesh {
        TriMesh::new(
            vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z],
            vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
        )
        .unwrap()
    }

    #[test]
    fn area_and_box_of_a_tetrahedron() {
        let m = tetra();
        let expected = 1.5 + 0.5 * 3f64.sqrt();
        assert!((m.area() - expected).abs() < 1e-12);
        assert_eq!(m.bounding_box(), (Vec3::ZERO, Vec3::ONE));
        assert!((m.diagonal() - 3f32.sqrt()).abs() < 1e-6);
    }

    #[test]
    fn new_rejects_bad_data() {
        let e = TriMesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::NAN], vec![[0, 1, 2]]).unwrap_err();
        assert!(e.to_string().contains("<memory>") && e.to_string().contains("vertex 2"), "{e}");
        let e = TriMesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 3]]).unwrap_err();
        assert!(e.to_string().contains("out of range"), "{e}");
        let e = TriMesh::new(vec![], vec![]).unwrap_err();
        assert!(e.to_string().contains("empty"), "{e}");
    }
}
