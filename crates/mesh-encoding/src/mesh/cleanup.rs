//! Mesh cleanup: drop degenerate and duplicate triangles, then remove vertices no triangle uses.
//!
//! * A triangle is **degenerate** when two of its indices are equal or its area is exactly zero
//!   (cross product computed in f64). Slivers with a tiny but non-zero area are kept: they are
//!   valid geometry for ray casting.
//! * Two triangles are **duplicates** when they use the same three vertices, in any order or
//!   orientation; the first one in file order is kept.
//! * A vertex is **unreferenced** when no remaining triangle uses it; vertices are renumbered
//!   keeping their order.

use std::collections::HashSet;

use super::TriMesh;

/// What [`TriMesh::cleanup`] removed.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct CleanupReport {
    /// Vertices no triangle referenced (including those a loader already skipped, see
    /// [`super::LoadReport`]).
    pub unreferenced_vertices: usize,
    /// Triangles with a repeated index or exactly zero area.
    pub degenerate_triangles: usize,
    /// Triangles that repeat the vertex set of an earlier one.
    pub duplicate_triangles: usize,
}

impl TriMesh {
    /// Removes degenerate and duplicate triangles and unreferenced vertices, in place.
    ///
    /// The result may be empty when every triangle was degenerate; [`TriMesh::validate`] says so.
    /// [`super::load_mesh`] reports that as an error naming the file.
    pub fn cleanup(&mut self) -> CleanupReport {
        let mut report = CleanupReport::default();
        let mut seen = HashSet::with_capacity(self.triangles.len());
        let mut kept = Vec::with_capacity(self.triangles.len());
        for (t, tri) in self.triangles.iter().enumerate() {
            let [a, b, c] = *tri;
            if a == b || b == c || a == c || self.doubled_area_vector(t) == glam::DVec3::ZERO {
                report.degenerate_triangles += 1;
                continue;
            }
            let mut key = [a, b, c];
            key.sort_unstable();
            if !seen.insert(key) {
                report.duplicate_triangles += 1;
                continue;
            }
            kept.push(*tri);
        }
        self.triangles = kept;

        let mut new_index = vec![u32::MAX; self.positions.len()];
        for tri in &self.triangles {
            for &i in tri {
                new_index[i as usize] = 0;
            }
        }
        let mut positions = Vec::with_capacity(self.positions.len());
        for (i, p) in self.positions.iter().enumerate() {
            if new_index[i] == 0 {
                new_index[i] = positions.len() as u32;
                positions.push(*p);
            }
        }
        report.unreferenced_vertices = self.positions.len() - positions.len();
        self.positions = positions;
        for tri in &mut self.triangles {
            for i in tri.iter_mut() {
                *i = new_index[*i as usize];
            }
        }
        report
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn removes_each_kind_of_defect() {
        let positions = vec![
            Vec3::ZERO,
            Vec3::X,
            Vec3::Y,
            Vec3::new(7.0, 7.0, 7.0), // unreferenced
            Vec3::new(2.0, 0.0, 0.0), // collinear with 0 and 1
            Vec3::Z,
        ];
        let triangles = vec![
            [0, 1, 2],
            [0, 0, 2], // repeated index
            [0, 1, 4], // zero area
            [2, 1, 0], // duplicate (flipped)
            [1, 2, 0], // duplicate (rotated)
            [0, 1, 5],
        ];
        let mut m = TriMesh::new(positions, triangles).unwrap();
        let r = m.cleanup();
        assert_eq!(
            r,
            CleanupReport {
                unreferenced_vertices: 2,
                degenerate_triangles: 2,
                duplicate_triangles: 2
            }
        );
        assert_eq!(m.positions, vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z]);
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 1, 3]]);
        m.validate().unwrap();
        // Idempotent.
        assert_eq!(m.cleanup(), CleanupReport::default());
    }

    #[test]
    fn all_degenerate_leaves_an_empty_mesh() {
        let mut m = TriMesh::new(vec![Vec3::ZERO, Vec3::X], vec![[0, 1, 1]]).unwrap();
        m.cleanup();
        assert!(m.validate().is_err());
    }
}
