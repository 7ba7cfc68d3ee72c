//! The shape model of DiLiGenT's ball: a sphere whose projection through the camera matches
//! the mask.
//!
//! 1. [`fit_circle`]: an algebraic least-squares circle (Kasa) through the mask's boundary,
//!    taken as the midpoints of the pixel edges between mask and background (they lie on the
//!    digitised outline itself, so the fit has no half-pixel bias).
//! 2. [`icosphere`]: a unit sphere triangulated by subdividing an icosahedron (uniform; level 5
//!    has 10 242 vertices, about 2 degrees between neighbours). It is the whole sphere, so the
//!    mesh is closed (the LBO encoding wants no boundary); the back is never seen.
//! 3. [`sphere_translation`]: with the world frame equal to the camera's (R = I) and the sphere
//!    at the origin, the translation that puts the sphere's centre on the ray through the
//!    circle's centre at the distance where its angular radius equals the circle's (averaged
//!    over eight directions, since the pixels need not be square).
//!
//! The result is checked against the benchmark's normal map by [`crate::normal_check`].

use crate::report::CircleFit;
use glam::{DMat3, DVec3, Vec3};
use mesh_encoding::TriMesh;

/// Fits a circle to the boundary of a row-major mask of `width` columns; `None` when the mask
/// has fewer than 8 boundary points or they are collinear.
pub fn fit_circle(mask: &[bool], width: usize) -> Option<CircleFit> {
    let height = mask.len() / width.max(1);
    let at = |x: usize, y: usize| mask[y * width + x];
    let mut pts: Vec<[f64; 2]> = Vec::new();
    for y in 0..height {
        for x in 0..width {
            if x + 1 < width && at(x, y) != at(x + 1, y) {
                pts.push([x as f64 + 1.0, y as f64 + 0.5]);
            }
            if y + 1 < height && at(x, y) != at(x, y + 1) {
                pts.push([x as f64 + 0.5, y as f64 + 1.0]);
            }
        }
    }
    if pts.len() < 8 {
        return None;
    }
    let n = pts.len() as f64;
    let (mx, my) =
        (pts.iter().map(|p| p[0]).sum::<f64>() / n, pts.iter().map(|p| p[1]).sum::<f64>() / n);
    // Normal equations of min sum (x^2 + y^2 + D x + E y + F)^2 in centred coordinates.
    let (mut a, mut b) = (DMat3::ZERO, DVec3::ZERO);
    for p in &pts {
        let (x, y) = (p[0] - mx, p[1] - my);
        let row = DVec3::new(x, y, 1.0);
        a += DMat3::from_cols(row * x, row * y, row);
        b -= row * (x * x + y * y);
    }
    if a.determinant().abs() < 1e-12 * n * n * n {
        return None;
    }
    let s = a.inverse() * b;
    let (cx, cy) = (-0.5 * s.x, -0.5 * s.y);
    let r2 = cx * cx + cy * cy - s.z;
    if r2.is_nan() || r2 <= 0.0 {
        return None;
    }
    let radius = r2.sqrt();
    let rms = (pts
        .iter()
        .map(|p| ((p[0] - mx - cx).hypot(p[1] - my - cy) - radius).powi(2))
        .sum::<f64>()
        / n)
        .sqrt();
    let area = mask.iter().filter(|&&m| m).count() as f64;
    Some(CircleFit {
        center: [cx + mx, cy + my],
        radius,
        rms_residual: rms,
        area_radius: (area / std::f64::consts::PI).sqrt(),
        boundary_points: pts.len(),
    })
}

/// A unit sphere from an icosahedron subdivided `level` times (10 4^level + 2 vertices),
/// counter-clockwise seen from outside.
pub fn icosphere(level: u32) -> TriMesh {
    let (v, f) = mesh_encoding::mesh::icosphere(level as usize);
    let positions = v.iter().map(|p| Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32)).collect();
    TriMesh { positions, triangles: f }
}

/// The camera translation (R = I) that makes a unit sphere at the origin project onto `circle`
/// through intrinsics `k` (OpenCV, pixel centres at +0.5).
pub fn sphere_translation(k: DMat3, circle: &CircleFit) -> DVec3 {
    let k_inv = k.inverse();
    let ray = |u: f64, v: f64| (k_inv * DVec3::new(u, v, 1.0)).normalize();
    let [u0, v0] = circle.center;
    let axis = ray(u0, v0);
    let alpha = (0..8)
        .map(|i| {
            let (s, c) = (i as f64 * std::f64::consts::FRAC_PI_4).sin_cos();
            axis.angle_between(ray(u0 + circle.radius * c, v0 + circle.radius * s))
        })
        .sum::<f64>()
        / 8.0;
    axis / alpha.sin()
}

#[cfg(test)]
mod tests {
    use super::*;
    use mesh_encoding::Topology;

    #[test]
    fn circle_fit_recovers_a_digitised_disc() {
        let (w, h, c, r) = (200usize, 150usize, [90.3, 70.8], 41.7);
        let mask: Vec<bool> = (0..w * h)
            .map(|p| {
                let (x, y) = ((p % w) as f64 + 0.5, (p / w) as f64 + 0.5);
                (x - c[0]).hypot(y - c[1]) < r
            })
            .collect();
        let f = fit_circle(&mask, w).unwrap();
        assert!((f.center[0] - c[0]).abs() < 0.05 && (f.center[1] - c[1]).abs() < 0.05, "{f:?}");
        assert!((f.radius - r).abs() < 0.05 && f.rms_residual < 0.3, "{f:?}");
        assert!(fit_circle(&[false; 100], 10).is_none());
    }

    #[test]
    fn icosphere_is_a_closed_unit_sphere() {
        let m = icosphere(3);
        assert_eq!(m.positions.len(), 10 * 64 + 2);
        assert!(Topology::of(&m).is_closed_manifold());
        for t in 0..m.triangles.len() {
            let c = m.corners(t);
            let centroid = (c[0] + c[1] + c[2]) / 3.0;
            assert!(m.doubled_area_vector(t).dot(centroid.as_dvec3()) > 0.0, "outward winding");
        }
    }

    #[test]
    fn placed_sphere_projects_onto_the_circle() {
        let k = DMat3::from_cols(
            DVec3::new(3772.0, 0.0, 0.0),
            DVec3::new(0.0, 3759.0, 0.0),
            DVec3::new(306.4, 255.6, 1.0),
        );
        let circle = CircleFit {
            center: [300.0, 260.0],
            radius: 70.0,
            rms_residual: 0.0,
            area_radius: 70.0,
            boundary_points: 100,
        };
        let t = sphere_translation(k, &circle);
        let centre = k * t;
        assert!(
            (centre.x / centre.z - 300.0).abs() < 1e-6
                && (centre.y / centre.z - 260.0).abs() < 1e-6
        );
        // The silhouette (tangent rays) lies within a fraction of a pixel of the circle.
        let d = t.length();
        let alpha = (1.0 / d).asin();
        let axis = t / d;
        let side = axis.cross(DVec3::Y).normalize();
        let edge = (axis * alpha.cos() + side * alpha.sin()) * 10.0;
        let e = k * edge;
        let r = (e.x / e.z - 300.0).hypot(e.y / e.z - 260.0);
        assert!((r - 70.0).abs() < 0.3, "{r}");
    }
}
