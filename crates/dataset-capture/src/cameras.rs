//! Cameras of a capture: nerfstudio / instant-ngp `transforms.json` or a COLMAP text model,
//! turned into one [`Frame`] per image with OpenCV intrinsics and world-to-camera pose
//! (docs/capture-format.md, "Cameras").

use crate::config::CaptureConfig;
use crate::error::{Error, Result};
use serde_json::Value;
use std::path::{Path, PathBuf};

/// One image of the capture and the camera that took it.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    /// The image's name as the cameras file gives it (the key into `lights.json`).
    pub name: String,
    /// The image file.
    pub image: PathBuf,
    /// Its mask, if any.
    pub mask: Option<PathBuf>,
    /// Image width and height in pixels.
    pub size: (u32, u32),
    /// OpenCV intrinsics K, rows (pixel centres at half-integers).
    pub k: [[f64; 3]; 3],
    /// World-to-camera rotation R, rows (OpenCV axes: x right, y down, looking down +z).
    pub r: [[f64; 3]; 3],
    /// World-to-camera translation: x_cam = R x_world + t.
    pub t: [f64; 3],
}

/// Reads the cameras the configuration names: a `transforms.json` file, or a folder with
/// COLMAP's `cameras.txt` and `images.txt`.
pub fn read(config: &CaptureConfig) -> Result<Vec<Frame>> {
    if config.cameras.is_dir() {
        crate::colmap::read(&config.cameras, &config.images, config.masks.as_deref())
    } else {
        read_transforms(&config.cameras)
    }
}

/// Checks that `m` is a rotation (orthonormal rows to 1e-4, determinant +1), naming the fault.
pub fn check_rotation(m: &[[f64; 3]; 3]) -> std::result::Result<(), String> {
    if m.iter().flatten().any(|x| !x.is_finite()) {
        return Err(format!("the rotation {m:?} has a non-finite entry"));
    }
    let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    if det.abs() < 1e-6 {
        return Err(format!("the pose is not invertible (determinant of its rotation {det:.3e})"));
    }
    if det < 0.0 {
        return Err(format!("the rotation is a mirror (determinant {det:.4})"));
    }
    for i in 0..3 {
        for j in 0..3 {
            let dot: f64 = (0..3).map(|c| m[i][c] * m[j][c]).sum();
            let want = if i == j { 1.0 } else { 0.0 };
            if (dot - want).abs() > 1e-4 {
                return Err(format!(
                    "the pose's 3 x 3 part is not a rotation (rows {i} and {j}: dot {dot:.6}, \
                     expected {want}): a scale or shear; poses must be rigid"
                ));
            }
        }
    }
    Ok(())
}

fn number(v: Option<&Value>) -> Option<f64> {
    v.and_then(Value::as_f64)
}

/// Intrinsics of a frame: the frame's own keys, else the file's.
struct Intrinsics {
    fx: f64,
    fy: f64,
    cx: f64,
    cy: f64,
    w: u32,
    h: u32,
}

fn intrinsics(top: &Value, frame: &Value) -> std::result::Result<Intrinsics, String> {
    let get = |key: &str| number(frame.get(key)).or_else(|| number(top.get(key)));
    let w = get("w").ok_or("no image width `w`")?;
    let h = get("h").ok_or("no image height `h`")?;
    for (key, v) in [("w", w), ("h", h)] {
        if !((1.0..=65535.0).contains(&v) && v.fract() == 0.0) {
            return Err(format!("`{key}` = {v} is not an image size"));
        }
    }
    let fx = match (get("fl_x"), get("camera_angle_x")) {
        (Some(f), _) => f,
        (None, Some(a)) => 0.5 * w / (0.5 * a).tan(),
        (None, None) => return Err("no focal length (`fl_x` or `camera_angle_x`)".into()),
    };
    let fy = match (get("fl_y"), get("camera_angle_y")) {
        (Some(f), _) => f,
        (None, Some(a)) => 0.5 * h / (0.5 * a).tan(),
        (None, None) => fx,
    };
    let cx = get("cx").unwrap_or(0.5 * w);
    let cy = get("cy").unwrap_or(0.5 * h);
    for (key, v) in [("fl_x", fx), ("fl_y", fy)] {
        if !(v.is_finite() && v > 0.0) {
            return Err(format!("focal length `{key}` = {v} must be positive"));
        }
    }
    if !(cx.is_finite() && cy.is_finite()) {
        return Err(format!("principal point ({cx}, {cy}) is not finite"));
    }
    for key in ["k1", "k2", "k3", "k4", "p1", "p2"] {
        if let Some(d) = get(key)
            && d != 0.0
        {
            return Err(format!(
                "lens distortion `{key}` = {d}: undistort the images first (distortion must be 0)"
            ));
        }
    }
    Ok(Intrinsics { fx, fy, cx, cy, w: w as u32, h: h as u32 })
}

/// Reads a nerfstudio / instant-ngp `transforms.json`.
pub fn read_transforms(path: &Path) -> Result<Vec<Frame>> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    let top: Value = serde_json::from_str(&text).map_err(|e| Error::input(path, e.to_string()))?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let frames = top
        .get("frames")
        .and_then(Value::as_array)
        .ok_or_else(|| Error::input(path, "no `frames` array"))?;
    if frames.is_empty() {
        return Err(Error::input(path, "`frames` is empty"));
    }
    frames
        .iter()
        .enumerate()
        .map(|(i, f)| {
            let fault = |m: String| Error::input(path, format!("frame {i}: {m}"));
            let name = f
                .get("file_path")
                .and_then(Value::as_str)
                .ok_or_else(|| fault("no `file_path`".into()))?;
            let fault = |m: String| Error::input(path, format!("frame {i} (`{name}`): {m}"));
            let k = intrinsics(&top, f).map_err(fault)?;
            let m = pose_matrix(f.get("transform_matrix")).map_err(fault)?;
            // OpenGL camera-to-world -> OpenCV: flip the camera's y and z axes.
            let c2w = [
                [m[0][0], -m[0][1], -m[0][2]],
                [m[1][0], -m[1][1], -m[1][2]],
                [m[2][0], -m[2][1], -m[2][2]],
            ];
            check_rotation(&c2w).map_err(fault)?;
            let centre = [m[0][3], m[1][3], m[2][3]];
            let (r, t) = world_to_camera(&c2w, centre);
            let mask = f.get("mask_path").and_then(Value::as_str).map(|m| dir.join(m));
            Ok(Frame {
                name: name.to_string(),
                image: resolve_image(&dir.join(name)),
                mask,
                size: (k.w, k.h),
                k: [[k.fx, 0.0, k.cx], [0.0, k.fy, k.cy], [0.0, 0.0, 1.0]],
                r,
                t,
            })
        })
        .collect()
}

/// R = C^T, t = -R c for a camera-to-world rotation C and centre c.
pub fn world_to_camera(c2w: &[[f64; 3]; 3], centre: [f64; 3]) -> ([[f64; 3]; 3], [f64; 3]) {
    let mut r = [[0.0; 3]; 3];
    for (i, row) in r.iter_mut().enumerate() {
        for (j, x) in row.iter_mut().enumerate() {
            *x = c2w[j][i];
        }
    }
    let t = std::array::from_fn(|i| -(0..3).map(|j| r[i][j] * centre[j]).sum::<f64>());
    (r, t)
}

/// The 3 x 4 part of a 4 x 4 or 3 x 4 `transform_matrix`.
fn pose_matrix(v: Option<&Value>) -> std::result::Result<[[f64; 4]; 3], String> {
    let rows = v.and_then(Value::as_array).ok_or("no `transform_matrix`")?;
    if !(rows.len() == 3 || rows.len() == 4) {
        return Err(format!("`transform_matrix` has {} rows, expected 4 (or 3)", rows.len()));
    }
    let mut m = [[0.0; 4]; 3];
    for (i, row) in m.iter_mut().enumerate() {
        let r = rows[i]
            .as_array()
            .filter(|r| r.len() == 4)
            .ok_or_else(|| format!("`transform_matrix` row {i} is not 4 numbers"))?;
        for (j, x) in row.iter_mut().enumerate() {
            *x = r[j]
                .as_f64()
                .ok_or_else(|| format!("`transform_matrix`[{i}][{j}] is not a number"))?;
            if !x.is_finite() {
                return Err(format!("`transform_matrix`[{i}][{j}] is not finite"));
            }
        }
    }
    Ok(m)
}

/// An image path as written, or with `.exr` / `.png` added where the name has no extension
/// (instant-ngp often leaves it out).
fn resolve_image(p: &Path) -> PathBuf {
    if p.extension().is_none() {
        for ext in ["exr", "png"] {
            let with = p.with_extension(ext);
            if with.exists() {
                return with;
            }
        }
    }
    p.to_path_buf()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_opengl_pose_becomes_opencv() {
        // A camera at (0, 0, 3) looking at the origin (down its -z in OpenGL terms).
        let json = r#"{"w": 64, "h": 48, "fl_x": 50, "fl_y": 50, "cx": 32, "cy": 24,
            "frames": [{"file_path": "a.exr", "transform_matrix":
              [[1,0,0,0],[0,1,0,0],[0,0,1,3],[0,0,0,1]]}]}"#;
        let dir = std::env::temp_dir().join(format!("transforms-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("transforms.json");
        std::fs::write(&p, json).unwrap();
        let f = read_transforms(&p).unwrap().remove(0);
        // The world origin is straight ahead, 3 units down the OpenCV camera's +z.
        let x: Vec<f64> = (0..3).map(|i| f.t[i]).collect();
        assert_eq!(x, vec![0.0, 0.0, 3.0]);
        // World +y (up) is image up: camera -y.
        assert_eq!(f.r[1], [0.0, -1.0, 0.0]);
        assert_eq!(f.size, (64, 48));
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn non_rigid_and_singular_poses_are_refused() {
        assert!(check_rotation(&[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]).is_ok());
        let e = check_rotation(&[[2.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]).unwrap_err();
        assert!(e.contains("not a rotation"), "{e}");
        let e = check_rotation(&[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 0.0]]).unwrap_err();
        assert!(e.contains("not invertible"), "{e}");
        let e = check_rotation(&[[-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]).unwrap_err();
        assert!(e.contains("mirror"), "{e}");
    }
}
