//! COLMAP's text model (`cameras.txt`, `images.txt`) as capture frames. COLMAP's poses are
//! world-to-camera in OpenCV axes, its pixel centres at half-integers: both as the scene format
//! has them.

use crate::cameras::{Frame, check_rotation};
use crate::error::{Error, Result};
use std::collections::HashMap;
use std::path::Path;

/// Intrinsics of one COLMAP camera.
struct Camera {
    w: u32,
    h: u32,
    k: [[f64; 3]; 3],
}

fn parse_camera(line: &str) -> std::result::Result<(u64, Camera), String> {
    let f: Vec<&str> = line.split_whitespace().collect();
    if f.len() < 4 {
        return Err(format!("`{line}`: expected CAMERA_ID MODEL WIDTH HEIGHT PARAMS..."));
    }
    let id: u64 = f[0].parse().map_err(|_| format!("camera id `{}`", f[0]))?;
    let w: u32 = f[2].parse().map_err(|_| format!("camera {id}: width `{}`", f[2]))?;
    let h: u32 = f[3].parse().map_err(|_| format!("camera {id}: height `{}`", f[3]))?;
    let p: Vec<f64> = f[4..]
        .iter()
        .map(|s| s.parse::<f64>().map_err(|_| format!("camera {id}: parameter `{s}`")))
        .collect::<std::result::Result<_, _>>()?;
    // (fx, fy, cx, cy, distortion parameters)
    let (fx, fy, cx, cy, dist): (f64, f64, f64, f64, &[f64]) = match (f[1], p.len()) {
        ("SIMPLE_PINHOLE", 3) => (p[0], p[0], p[1], p[2], &[]),
        ("PINHOLE", 4) => (p[0], p[1], p[2], p[3], &[]),
        ("SIMPLE_RADIAL", 4) | ("RADIAL", 5) => (p[0], p[0], p[1], p[2], &p[3..]),
        ("OPENCV", 8) => (p[0], p[1], p[2], p[3], &p[4..]),
        (model, n) => {
            return Err(format!(
                "camera {id}: model {model} with {n} parameters is not supported (SIMPLE_PINHOLE, \
                 PINHOLE, or SIMPLE_RADIAL, RADIAL, OPENCV without distortion)"
            ));
        }
    };
    if dist.iter().any(|&d| d != 0.0) {
        return Err(format!(
            "camera {id}: lens distortion {dist:?}: undistort the images first (COLMAP's \
             image_undistorter writes a PINHOLE model)"
        ));
    }
    if !(fx > 0.0 && fy > 0.0 && fx.is_finite() && fy.is_finite()) || w == 0 || h == 0 {
        return Err(format!("camera {id}: focal lengths ({fx}, {fy}) or size {w} x {h} invalid"));
    }
    Ok((id, Camera { w, h, k: [[fx, 0.0, cx], [0.0, fy, cy], [0.0, 0.0, 1.0]] }))
}

/// The rotation of a quaternion (w, x, y, z), normalised; an error for a zero or non-finite one.
fn quaternion_rotation(q: [f64; 4]) -> std::result::Result<[[f64; 3]; 3], String> {
    let n = q.iter().map(|x| x * x).sum::<f64>().sqrt();
    if !(n.is_finite() && n > 1e-12) {
        return Err(format!("quaternion {q:?} is zero or not finite: the pose is not invertible"));
    }
    let [w, x, y, z] = q.map(|c| c / n);
    Ok([
        [1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - w * z), 2.0 * (x * z + w * y)],
        [2.0 * (x * y + w * z), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - w * x)],
        [2.0 * (x * z - w * y), 2.0 * (y * z + w * x), 1.0 - 2.0 * (x * x + y * y)],
    ])
}

/// Lines that are not comments, in order (empty ones kept: `images.txt` pairs lines).
fn content_lines(text: &str) -> Vec<&str> {
    text.lines().filter(|l| !l.trim_start().starts_with('#')).collect()
}

/// Reads `dir/cameras.txt` and `dir/images.txt`; image names resolve against `images`, masks
/// (if `masks` is given) are `masks/<name>.png`.
pub fn read(dir: &Path, images: &Path, masks: Option<&Path>) -> Result<Vec<Frame>> {
    let cam_path = dir.join("cameras.txt");
    let text = std::fs::read_to_string(&cam_path).map_err(|e| Error::io(&cam_path, e))?;
    let mut cameras = HashMap::new();
    for line in content_lines(&text).into_iter().filter(|l| !l.trim().is_empty()) {
        let (id, c) = parse_camera(line).map_err(|f| Error::input(&cam_path, f))?;
        cameras.insert(id, c);
    }
    let img_path = dir.join("images.txt");
    let text = std::fs::read_to_string(&img_path).map_err(|e| Error::io(&img_path, e))?;
    let lines = content_lines(&text);
    let mut frames = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        let line = lines[i].trim();
        if line.is_empty() {
            i += 1;
            continue;
        }
        let fault = |m: String| Error::input(&img_path, m);
        let f: Vec<&str> = line.split_whitespace().collect();
        if f.len() < 10 {
            return Err(fault(format!(
                "`{line}`: expected IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME"
            )));
        }
        let nums: Vec<f64> = f[1..8]
            .iter()
            .map(|s| {
                s.parse::<f64>()
                    .map_err(|_| fault(format!("image {}: `{s}` is not a number", f[0])))
            })
            .collect::<Result<_>>()?;
        let name = f[9..].join(" ");
        let fault = |m: String| Error::input(&img_path, format!("image {} (`{name}`): {m}", f[0]));
        let r = quaternion_rotation([nums[0], nums[1], nums[2], nums[3]]).map_err(fault)?;
        check_rotation(&r).map_err(fault)?;
        let t = [nums[4], nums[5], nums[6]];
        if t.iter().any(|x| !x.is_finite()) {
            return Err(fault(format!("translation {t:?} is not finite")));
        }
        let cam_id: u64 = f[8].parse().map_err(|_| fault(format!("camera id `{}`", f[8])))?;
        let cam = cameras
            .get(&cam_id)
            .ok_or_else(|| fault(format!("camera {cam_id} is not in {}", cam_path.display())))?;
        frames.push(Frame {
            image: images.join(&name),
            mask: masks.map(|m| m.join(format!("{name}.png"))),
            name,
            size: (cam.w, cam.h),
            k: cam.k,
            r,
            t,
        });
        i += 2; // the header line and its (possibly empty) 2D-points line
    }
    if frames.is_empty() {
        return Err(Error::input(&img_path, "no images"));
    }
    Ok(frames)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_colmap_model_reads() {
        let dir = std::env::temp_dir().join(format!("colmap-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(
            dir.join("cameras.txt"),
            "# Camera list\n1 PINHOLE 64 48 50 51 32 24\n2 OPENCV 64 48 50 50 32 24 0 0 0 0\n",
        )
        .unwrap();
        // A 90-degree turn about z: q = (cos 45, 0, 0, sin 45).
        let h = std::f64::consts::FRAC_1_SQRT_2;
        std::fs::write(
            dir.join("images.txt"),
            format!(
                "# Image list\n1 1 0 0 0 0 0 3 1 a.png\n1 2 3 4\n2 {h} 0 0 {h} 1 2 3 2 b c.png\n\n"
            ),
        )
        .unwrap();
        let f = read(&dir, Path::new("/imgs"), Some(Path::new("/masks"))).unwrap();
        assert_eq!(f.len(), 2);
        assert_eq!(f[0].t, [0.0, 0.0, 3.0]);
        assert_eq!(f[0].k[1][1], 51.0);
        assert_eq!(f[1].name, "b c.png");
        assert_eq!(f[1].mask.as_deref(), Some(Path::new("/masks/b c.png.png")));
        assert!((f[1].r[0][1] + 1.0).abs() < 1e-12 && (f[1].r[1][0] - 1.0).abs() < 1e-12);
        std::fs::write(dir.join("cameras.txt"), "1 OPENCV 64 48 50 50 32 24 0.1 0 0 0\n").unwrap();
        let e = read(&dir, Path::new("/imgs"), None).unwrap_err().to_string();
        assert!(e.contains("cameras.txt") && e.contains("distortion"), "{e}");
        std::fs::write(dir.join("cameras.txt"), "1 PINHOLE 64 48 50 51 32 24\n").unwrap();
        std::fs::write(dir.join("images.txt"), "1 0 0 0 0 0 0 3 1 a.png\n\n").unwrap();
        let e = read(&dir, Path::new("/imgs"), None).unwrap_err().to_string();
        assert!(e.contains("images.txt") && e.contains("not invertible"), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
