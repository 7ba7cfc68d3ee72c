//! Standard test views for benchmarks and figures: cameras on a sphere around a normalised mesh,
//! looking at the origin, with light directions drawn in the hemisphere around each camera's
//! direction (like DiLiGenT-MV's light dome; spec section 6, semi-synthetic scenes). Deterministic
//! for a given seed.

use glam::Vec3;

use crate::camera::Camera;
use crate::precompute::View;

/// `views` views of `size x size` pixels at distance `distance` from the origin, field of view
/// `fov_y_deg`, each with `lights` light directions within 60 degrees of the direction towards the
/// camera. Meant for meshes normalised into the unit sphere.
pub fn orbit_views(
    views: usize,
    lights: usize,
    size: u32,
    distance: f32,
    fov_y_deg: f32,
    seed: u64,
) -> Vec<View> {
    let mut rng = stdx::rng::SplitMix64::new(seed);
    let mut uniform = move || rng.next_f32();
    let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
    (0..views)
        .map(|i| {
            // Fibonacci points on the sphere, restricted to elevations in [-30, 60] degrees.
            let z = -0.5 + 1.366 * (i as f32 + 0.5) / views as f32;
            let r = (1.0 - z * z).sqrt();
            let phi = golden * i as f32;
            let dir = Vec3::new(r * phi.cos(), r * phi.sin(), z);
            let camera =
                Camera::look_at(distance * dir, Vec3::ZERO, Vec3::Z, fov_y_deg, size, size)
                    .expect("orbit camera is valid");
            let (t, b) = dir.any_orthonormal_pair();
            let lights = (0..lights)
                .map(|_| {
                    let cos_max = 60f32.to_radians().cos();
                    let c = 1.0 - uniform() * (1.0 - cos_max);
                    let s = (1.0 - c * c).max(0.0).sqrt();
                    let a = std::f32::consts::TAU * uniform();
                    (c * dir + s * a.cos() * t + s * a.sin() * b).normalize()
                })
                .collect();
            View { camera, lights, mask: None }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lights_lie_in_the_cone_around_each_camera() {
        let views = orbit_views(20, 42, 64, 3.0, 40.0, 1);
        assert_eq!(views.len(), 20);
        for v in &views {
            let to_cam = v.camera.center().normalize();
            assert_eq!(v.lights.len(), 42);
            for l in &v.lights {
                assert!(l.is_normalized() && l.dot(to_cam) >= 0.5 - 1e-5);
            }
        }
        assert_eq!(views, orbit_views(20, 42, 64, 3.0, 40.0, 1));
    }
}
