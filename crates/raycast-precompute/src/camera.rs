//! Pinhole cameras in the OpenCV convention (as DiLiGenT-MV calibrates them).
//!
//! Camera axes: x right, y down, z forward (the viewing direction). A world point x_w maps to
//! camera coordinates x_c = R x_w + t and to pixel coordinates (u, v) = (K x_c).xy / (K x_c).z,
//! with K = [[fx, s, cx], [0, fy, cy], [0, 0, 1]]. Pixel (i, j) (column i, row j) covers
//! [i, i + 1) x [j, j + 1); its centre, where its ray passes, is (i + 0.5, j + 0.5). The camera
//! centre in world space is C = -R^T t. Units are the mesh's units.

use glam::{Mat3, Vec2, Vec3};

use crate::error::{Error, Result};

/// A calibrated pinhole camera, see the module documentation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// Intrinsic matrix K (as a glam matrix: `k * x_c` is the homogeneous pixel).
    pub k: Mat3,
    /// World-to-camera rotation R.
    pub r: Mat3,
    /// World-to-camera translation t.
    pub t: Vec3,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    k_inv: Mat3,
}

/// Builds K from focal lengths and principal point (in pixels, no skew).
pub fn intrinsics(fx: f32, fy: f32, cx: f32, cy: f32) -> Mat3 {
    Mat3::from_cols(Vec3::new(fx, 0.0, 0.0), Vec3::new(0.0, fy, 0.0), Vec3::new(cx, cy, 1.0))
}

/// A 3 x 3 matrix from row-major rows, as OpenCV and calibration files write them.
pub fn mat3_from_rows(rows: [[f32; 3]; 3]) -> Mat3 {
    Mat3::from_cols_array_2d(&rows).transpose()
}

impl Camera {
    /// A camera from OpenCV intrinsics K and extrinsics R, t.
    ///
    /// # Errors
    /// [`Error::Camera`] when a value is not finite, K is not upper triangular with positive
    /// focal lengths and `K[2][2] = 1`, R is not a rotation (orthonormal, det 1, tolerance 1e-3)
    /// or the image is empty.
    pub fn from_opencv(k: Mat3, r: Mat3, t: Vec3, width: u32, height: u32) -> Result<Self> {
        let bad = |m: &str| Err(Error::Camera(m.to_string()));
        if !(k.is_finite() && r.is_finite() && t.is_finite()) {
            return bad("non-finite K, R or t");
        }
        if width == 0 || height == 0 {
            return bad("empty image");
        }
        let (fx, fy) = (k.x_axis.x, k.y_axis.y);
        if !(fx > 0.0 && fy > 0.0) || k.x_axis.y != 0.0 || k.x_axis.z != 0.0 || k.y_axis.z != 0.0 {
            return bad("K must be upper triangular with positive focal lengths");
        }
        if (k.z_axis.z - 1.0).abs() > 1e-6 {
            return bad("K[2][2] must be 1");
        }
        let orth = (r * r.transpose() - Mat3::IDENTITY).to_cols_array();
        if orth.iter().any(|e| e.abs() > 1e-3) || (r.determinant() - 1.0).abs() > 1e-3 {
            return bad("R is not a rotation (orthonormal with determinant 1)");
        }
        Ok(Camera { k, r, t, width, height, k_inv: k.inverse() })
    }

    /// A camera at `eye` looking at `target`, with `up` pointing up in the image (image y runs
    /// down, against `up`), vertical field of view `fov_y_deg` and the principal point at the
    /// image centre.
    ///
    /// # Errors
    /// [`Error::Camera`] when eye and target coincide, `up` is parallel to the viewing direction
    /// or the field of view is not in (0, 180).
    pub fn look_at(
        eye: Vec3,
        target: Vec3,
        up: Vec3,
        fov_y_deg: f32,
        width: u32,
        height: u32,
    ) -> Result<Self> {
        if !(fov_y_deg > 0.0 && fov_y_deg < 180.0) {
            return Err(Error::Camera(format!("field of view {fov_y_deg} deg not in (0, 180)")));
        }
        let forward = (target - eye)
            .try_normalize()
            .ok_or_else(|| Error::Camera("eye and target coincide".into()))?;
        let right = forward
            .cross(up)
            .try_normalize()
            .ok_or_else(|| Error::Camera("up is parallel to the viewing direction".into()))?;
        let down = forward.cross(right);
        let r = mat3_from_rows([right.to_array(), down.to_array(), forward.to_array()]);
        let f = 0.5 * height as f32 / (0.5 * fov_y_deg.to_radians()).tan();
        let k = intrinsics(f, f, 0.5 * width as f32, 0.5 * height as f32);
        Camera::from_opencv(k, r, -(r * eye), width, height)
    }

    /// The camera centre in world space, C = -R^T t.
    pub fn center(&self) -> Vec3 {
        -(self.r.transpose() * self.t)
    }

    /// Number of pixels, width x height.
    pub fn pixel_count(&self) -> usize {
        self.width as usize * self.height as usize
    }

    /// Unit world-space direction of the ray through pixel coordinates (u, v) (continuous; the
    /// centre of pixel (i, j) is (i + 0.5, j + 0.5)).
    pub fn direction_through(&self, u: f32, v: f32) -> Vec3 {
        (self.r.transpose() * (self.k_inv * Vec3::new(u, v, 1.0))).normalize()
    }

    /// Origin and unit direction of the ray through the centre of pixel `index` (row-major,
    /// `index = row * width + column`).
    pub fn pixel_ray(&self, index: usize) -> (Vec3, Vec3) {
        let (i, j) = (index % self.width as usize, index / self.width as usize);
        (self.center(), self.direction_through(i as f32 + 0.5, j as f32 + 0.5))
    }

    /// Pixel coordinates of a world point, or `None` when it is not in front of the camera.
    pub fn project(&self, x_world: Vec3) -> Option<Vec2> {
        let p = self.k * (self.r * x_world + self.t);
        (p.z > 0.0).then(|| Vec2::new(p.x / p.z, p.y / p.z))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn look_at_follows_the_opencv_axes() {
        let cam =
            Camera::look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 60.0, 640, 480).unwrap();
        assert!((cam.center() - Vec3::new(0.0, 0.0, 5.0)).length() < 1e-5);
        // The target projects to the image centre; +x world is to the right, +y world is up.
        let c = cam.project(Vec3::ZERO).unwrap();
        assert!((c - Vec2::new(320.0, 240.0)).length() < 1e-3);
        assert!(cam.project(Vec3::X).unwrap().x > 320.0);
        assert!(cam.project(Vec3::Y).unwrap().y < 240.0);
        // A point behind the camera does not project.
        assert!(cam.project(Vec3::new(0.0, 0.0, 6.0)).is_none());
        // Top edge of the image at half the field of view.
        let d = cam.direction_through(320.0, 0.0);
        assert!((d.angle_between(-Vec3::Z).to_degrees() - 30.0).abs() < 1e-3);
    }

    #[test]
    fn pixel_rays_reproject_to_pixel_centres() {
        let k = intrinsics(500.0, 520.0, 100.3, 80.7);
        let r = glam::Mat3::from_rotation_y(0.3) * glam::Mat3::from_rotation_x(-0.2);
        let cam = Camera::from_opencv(k, r, Vec3::new(0.1, -0.2, 3.0), 200, 160).unwrap();
        for index in [0, 77, 200 * 160 - 1, 12345] {
            let (o, d) = cam.pixel_ray(index);
            let p = cam.project(o + 2.0 * d).unwrap();
            let expected = Vec2::new((index % 200) as f32 + 0.5, (index / 200) as f32 + 0.5);
            assert!((p - expected).length() < 1e-3, "{p} {expected}");
        }
    }

    #[test]
    fn rejects_bad_parameters() {
        let k = intrinsics(500.0, 500.0, 50.0, 50.0);
        let scaled = Mat3::from_diagonal(Vec3::splat(2.0));
        assert!(Camera::from_opencv(k, scaled, Vec3::ZERO, 100, 100).is_err());
        let mirror = Mat3::from_diagonal(Vec3::new(1.0, 1.0, -1.0));
        assert!(Camera::from_opencv(k, mirror, Vec3::ZERO, 100, 100).is_err());
        assert!(Camera::from_opencv(k, Mat3::IDENTITY, Vec3::NAN, 100, 100).is_err());
        assert!(Camera::from_opencv(k, Mat3::IDENTITY, Vec3::ZERO, 0, 100).is_err());
        assert!(Camera::look_at(Vec3::Y, Vec3::ZERO, Vec3::Y, 40.0, 10, 10).is_err());
        assert!(Camera::look_at(Vec3::Z, Vec3::ZERO, Vec3::Y, 180.0, 10, 10).is_err());
    }
}
