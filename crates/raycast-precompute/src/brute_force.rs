//! The brute-force reference: every ray against every triangle, in f64, with the Möller-Trumbore
//! test. It defines what the BVH tracer must agree with (tests) and the baseline of the speed
//! ratio (bench). Barycentrics follow the crate convention: the hit point is
//! (1 - b1 - b2) v0 + b1 v1 + b2 v2 for triangle [v0, v1, v2].

use glam::{DVec3, Vec3};
use mesh_encoding::TriMesh;

use crate::tracer::Hit;

/// Möller-Trumbore in f64: `(t, b1, b2)` when the ray `origin + t dir` with `t in [t_min, t_max]`
/// hits the triangle (both sides; edges and corners count as inside), else `None`.
pub fn intersect_triangle(
    origin: DVec3,
    dir: DVec3,
    v: [DVec3; 3],
    t_min: f64,
    t_max: f64,
) -> Option<(f64, f64, f64)> {
    let e1 = v[1] - v[0];
    let e2 = v[2] - v[0];
    let p = dir.cross(e2);
    let det = e1.dot(p);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let inv = 1.0 / det;
    let s = origin - v[0];
    let b1 = s.dot(p) * inv;
    let q = s.cross(e1);
    let b2 = dir.dot(q) * inv;
    if b1 < 0.0 || b2 < 0.0 || b1 + b2 > 1.0 {
        return None;
    }
    let t = e2.dot(q) * inv;
    (t >= t_min && t <= t_max).then_some((t, b1, b2))
}

/// Barycentrics (b1, b2) of the point where the ray meets the plane of the triangle, in f64, with
/// no inside test (used to refine a hit found in f32).
pub fn plane_barycentrics(origin: DVec3, dir: DVec3, v: [DVec3; 3]) -> (f64, f64) {
    let e1 = v[1] - v[0];
    let e2 = v[2] - v[0];
    let p = dir.cross(e2);
    let det = e1.dot(p);
    if det == 0.0 {
        return (0.0, 0.0);
    }
    let s = origin - v[0];
    (s.dot(p) / det, dir.dot(s.cross(e1)) / det)
}

/// Brute-force ray caster over a mesh.
#[derive(Debug, Clone)]
pub struct BruteForce<'a> {
    mesh: &'a TriMesh,
}

impl<'a> BruteForce<'a> {
    /// A reference caster for `mesh`.
    pub fn new(mesh: &'a TriMesh) -> Self {
        BruteForce { mesh }
    }

    fn corners(&self, t: usize) -> [DVec3; 3] {
        self.mesh.corners(t).map(|p| p.as_dvec3())
    }

    /// Closest hit with `t in [0, t_max]`; `dir` need not be unit (t is in units of `dir`).
    pub fn closest_hit(&self, origin: Vec3, dir: Vec3, t_max: f32) -> Option<Hit> {
        let (o, d) = (origin.as_dvec3(), dir.as_dvec3());
        let mut best: Option<(f64, usize, f64, f64)> = None;
        for tri in 0..self.mesh.triangle_count() {
            let limit = best.map_or(f64::from(t_max), |b| b.0);
            if let Some((t, b1, b2)) = intersect_triangle(o, d, self.corners(tri), 0.0, limit)
                && best.is_none_or(|b| t < b.0)
            {
                best = Some((t, tri, b1, b2));
            }
        }
        best.map(|(t, tri, b1, b2)| Hit {
            triangle: tri as u32,
            t: t as f32,
            barycentrics: [b1 as f32, b2 as f32],
        })
    }

    /// Whether anything is hit with `t in [0, t_max]`.
    pub fn occluded(&self, origin: Vec3, dir: Vec3, t_max: f32) -> bool {
        let (o, d) = (origin.as_dvec3(), dir.as_dvec3());
        (0..self.mesh.triangle_count())
            .any(|tri| intersect_triangle(o, d, self.corners(tri), 0.0, f64::from(t_max)).is_some())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn moller_trumbore_on_one_triangle() {
        let v = [DVec3::ZERO, DVec3::X, DVec3::Y];
        let (t, b1, b2) =
            intersect_triangle(DVec3::new(0.2, 0.3, 1.0), -DVec3::Z, v, 0.0, 10.0).unwrap();
        assert!((t - 1.0).abs() < 1e-15 && (b1 - 0.2).abs() < 1e-15 && (b2 - 0.3).abs() < 1e-15);
        // From below, too (no culling); outside; beyond t_max; parallel.
        assert!(intersect_triangle(DVec3::new(0.2, 0.3, -1.0), DVec3::Z, v, 0.0, 10.0).is_some());
        assert!(intersect_triangle(DVec3::new(0.8, 0.3, 1.0), -DVec3::Z, v, 0.0, 10.0).is_none());
        assert!(intersect_triangle(DVec3::new(0.2, 0.3, 1.0), -DVec3::Z, v, 0.0, 0.5).is_none());
        assert!(intersect_triangle(DVec3::new(0.2, 0.3, 1.0), DVec3::X, v, 0.0, 10.0).is_none());
        let (p1, p2) = plane_barycentrics(DVec3::new(0.8, 0.3, 1.0), -DVec3::Z, v);
        assert!((p1 - 0.8).abs() < 1e-15 && (p2 - 0.3).abs() < 1e-15);
    }
}
