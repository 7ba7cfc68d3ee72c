//! Per-vertex normals from the triangles around each vertex.
//!
//! The default ([`NormalWeighting::Angle`], Thürmer and Wüthrich 1998) weights each incident
//! triangle's unit normal by the triangle's interior angle at the vertex; it does not depend on
//! how a flat region is triangulated. [`NormalWeighting::Area`] weights by triangle area (the sum
//! of unnormalised cross products). The spec leaves the choice open (section 6, UNVERIFIED), so
//! both are offered. Accumulation is in f64; results are unit f32 vectors, oriented by the
//! triangles' counter-clockwise winding.
//!
//! A vertex whose weighted sum vanishes (for example two coincident opposite triangles) falls
//! back to the area-weighted sum, then to +z, so the result is always a finite unit vector.

use glam::{DVec3, Vec3};

use super::TriMesh;

/// How incident triangle normals are weighted in [`TriMesh::vertex_normals`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub enum NormalWeighting {
    /// Weight by the interior angle at the vertex (default).
    #[default]
    Angle,
    /// Weight by triangle area.
    Area,
}

impl TriMesh {
    /// Unit vertex normals, one per vertex, see the module documentation.
    pub fn vertex_normals(&self, weighting: NormalWeighting) -> Vec<Vec3> {
        let mut angle_sum = vec![DVec3::ZERO; self.positions.len()];
        let mut area_sum = vec![DVec3::ZERO; self.positions.len()];
        for (t, tri) in self.triangles.iter().enumerate() {
            let n2 = self.doubled_area_vector(t);
            let p = self.corners(t).map(|p| p.as_dvec3());
            for k in 0..3 {
                area_sum[tri[k] as usize] += n2;
                if weighting == NormalWeighting::Angle {
                    let e1 = p[(k + 1) % 3] - p[k];
                    let e2 = p[(k + 2) % 3] - p[k];
                    let angle = e1.angle_between(e2);
                    if let Some(n) = n2.try_normalize()
                        && angle.is_finite()
                    {
                        angle_sum[tri[k] as usize] += angle * n;
                    }
                }
            }
        }
        let primary = if weighting == NormalWeighting::Angle { &angle_sum } else { &area_sum };
        primary
            .iter()
            .zip(&area_sum)
            .map(|(p, a)| {
                p.try_normalize().or_else(|| a.try_normalize()).unwrap_or(DVec3::Z).as_vec3()
            })
            .collect()
    }
}

/// Interpolates three vertex normals with barycentric weights `(1 - b1 - b2, b1, b2)` and
/// normalises the result; falls back to `fallback` when the sum vanishes.
pub fn interpolate_normal(n: [Vec3; 3], b1: f32, b2: f32, fallback: Vec3) -> Vec3 {
    ((1.0 - b1 - b2) * n[0] + b1 * n[1] + b2 * n[2]).try_normalize().unwrap_or(fallback)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit cube's corner normal is (±1, ±1, ±1)/sqrt(3) under angle weighting whatever the
    /// triangulation; area weighting depends on how many triangles touch the corner.
    #[test]
    fn cube_corner_normals() {
        let mut positions = Vec::new();
        for i in 0..8u32 {
            positions.push(Vec3::new((i & 1) as f32, ((i >> 1) & 1) as f32, (i >> 2) as f32));
        }
        // Quads (outward, counter-clockwise), split along one diagonal each.
        let quads = [
            [0, 2, 3, 1], // z = 0, normal -z
            [4, 5, 7, 6], // z = 1
            [0, 1, 5, 4], // y = 0
            [2, 6, 7, 3], // y = 1
            [0, 4, 6, 2], // x = 0
            [1, 3, 7, 5], // x = 1
        ];
        let triangles: Vec<[u32; 3]> =
            quads.iter().flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]).collect();
        let m = TriMesh::new(positions.clone(), triangles).unwrap();
        let n = m.vertex_normals(NormalWeighting::Angle);
        for (p, n) in positions.iter().zip(&n) {
            let expected = (*p - Vec3::splat(0.5)).normalize();
            assert!((*n - expected).length() < 1e-6, "{p} {n}");
        }
        let area = m.vertex_normals(NormalWeighting::Area);
        assert!(area.iter().all(|n| n.is_normalized()));
        // Vertex 1 touches one triangle of faces z=0 and y=0 but two of x=1: area weighting
        // tilts its normal towards +x.
        assert!((area[1] - n[1]).length() > 1e-3);
        assert!(area[1].x > n[1].x);
    }

    #[test]
    fn vanishing_sum_falls_back_to_a_unit_vector() {
        let m =
            TriMesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2], [0, 2, 1]]).unwrap();
        for w in [NormalWeighting::Angle, NormalWeighting::Area] {
            assert!(m.vertex_normals(w).iter().all(|n| *n == Vec3::Z));
        }
    }

    #[test]
    fn interpolation_is_unit() {
        let n = interpolate_normal([Vec3::X, Vec3::Y, Vec3::Z], 0.3, 0.3, Vec3::Z);
        assert!(n.is_normalized());
        let opposite = interpolate_normal([Vec3::X, -Vec3::X, Vec3::Z], 0.5, 0.0, Vec3::Y);
        assert_eq!(opposite, Vec3::Y);
    }
}
