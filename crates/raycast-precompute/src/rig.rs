//! Camera rigs around a mesh normalised into the unit sphere: cameras on a Fibonacci orbit
//! looking at the origin, each with light directions in a cone around its direction (like
//! DiLiGenT-MV's light dome). Deterministic for a given seed. The scene crate's `orbit` picks
//! the dataset's rig from a scene's settings; the benchmarks and tests here use their own.

use glam::Vec3;

use crate::camera::Camera;
use crate::error::Result;
use crate::precompute::View;

/// `views` views of `width x height` pixels at distance `distance` from the origin, vertical
/// field of view `fov_y_deg`, each with `lights` light directions within 60 degrees of the
/// direction towards the camera (drawn from SplitMix64 seeded with `seed`, view by view).
pub fn orbit_views(
    views: usize,
    lights: usize,
    (width, height): (u32, u32),
    distance: f32,
    fov_y_deg: f32,
    seed: u64,
) -> Result<Vec<View>> {
    let mut rng = stdx::rng::SplitMix64::new(seed);
    (0..views)
        .map(|i| {
            let dir = orbit_direction(i, views);
            let camera =
                Camera::look_at(distance * dir, Vec3::ZERO, Vec3::Z, fov_y_deg, width, height)?;
            let lights = cone_directions(dir, lights, 60.0, || rng.next_f32());
            let lights = lights.into_iter().map(crate::Light::Directional).collect();
            Ok(View { camera, lights, mask: None })
        })
        .collect()
}

/// Unit direction from the origin to camera `index` of `count` on the orbit: Fibonacci points
/// on the sphere, restricted to elevations in [-30, 60] degrees.
pub fn orbit_direction(index: usize, count: usize) -> Vec3 {
    let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
    let z = -0.5 + 1.366 * (index as f32 + 0.5) / count as f32;
    let r = (1.0 - z * z).sqrt();
    let phi = golden * index as f32;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// `count` unit directions within `max_angle_deg` of the unit vector `axis`, uniform in solid
/// angle; `uniform` supplies numbers in [0, 1), two per direction.
pub fn cone_directions(
    axis: Vec3,
    count: usize,
    max_angle_deg: f32,
    mut uniform: impl FnMut() -> f32,
) -> Vec<Vec3> {
    let (t, b) = axis.any_orthonormal_pair();
    let cos_max = max_angle_deg.to_radians().cos();
    (0..count)
        .map(|_| {
            let c = 1.0 - uniform() * (1.0 - cos_max);
            let s = (1.0 - c * c).max(0.0).sqrt();
            let a = std::f32::consts::TAU * uniform();
            (c * axis + s * a.cos() * t + s * a.sin() * b).normalize()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orbit_directions_are_unit_and_within_the_elevation_band() {
        for i in 0..20 {
            let d = orbit_direction(i, 20);
            assert!(d.is_normalized(), "{d}");
            let elevation = d.z.asin().to_degrees();
            assert!((-30.1..=60.1).contains(&elevation), "{elevation}");
        }
    }

    #[test]
    fn orbit_views_are_deterministic_and_light_their_cameras() {
        let views = orbit_views(20, 42, (64, 48), 3.0, 40.0, 1).unwrap();
        assert_eq!(views.len(), 20);
        for v in &views {
            let to_cam = v.camera.center().normalize();
            assert_eq!(v.lights.len(), 42);
            assert!(v.lights.iter().all(|l| l.direction().unwrap().dot(to_cam) >= 0.5 - 1e-5));
        }
        assert_eq!(views, orbit_views(20, 42, (64, 48), 3.0, 40.0, 1).unwrap());
        assert!(orbit_views(2, 1, (64, 64), 3.0, 190.0, 1).is_err());
    }

    #[test]
    fn cone_directions_lie_in_the_cone() {
        let mut rng = stdx::rng::SplitMix64::new(1);
        for i in 0..20 {
            let axis = orbit_direction(i, 20);
            let lights = cone_directions(axis, 42, 60.0, || rng.next_f32());
            assert_eq!(lights.len(), 42);
            for l in &lights {
                assert!(l.is_normalized() && l.dot(axis) >= 0.5 - 1e-5);
            }
        }
    }
}
