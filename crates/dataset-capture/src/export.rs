//! Any scene directory written out in the capture format: the test of the importer (a capture
//! of a semi-synthetic scene must import to the same samples) and a worked example for users.
//!
//! Per (view, light) pair of the scene's splits (train views with their train lights, test
//! views with their test lights): `images/vVV_lLL.exr` (the observed radiance), and per view
//! `masks/vVV.png` (the scene's mask); `transforms.json` (OpenGL camera-to-world, as nerfstudio
//! writes it), `lights.json`, `mesh.ply` and `capture.toml`.

use crate::error::{Error, Result};
use crate::lights::{CaptureLight, LightEntry, LightsFile, RawEntry};
use scene::SceneDataset;
use serde_json::json;
use std::path::Path;

/// Writes the scene at `scene_dir` as a capture at `out` (assembled in a temporary sibling,
/// renamed into place when complete).
pub fn export_capture(scene_dir: &Path, out: &Path) -> Result<()> {
    let scene = SceneDataset::open(scene_dir)?;
    let m = &scene.manifest;
    stdx::fs::write_dir_atomic(out, &["images", "masks"], |tmp: &Path| -> Result<()> {
        let mut frames = Vec::new();
        let mut lights = Vec::new();
        for (vi, v) in m.views.iter().enumerate() {
            let (w, h) = (m.config.settings.width, m.config.settings.height);
            let mask_rel = format!("masks/v{vi:02}.png");
            std::fs::copy(scene_dir.join(&mask_rel), tmp.join(&mask_rel))
                .map_err(|e| Error::io(scene_dir.join(&mask_rel), e))?;
            let c2w = camera_to_world_gl(v.r, v.t);
            for (li, l) in v.lights.iter().enumerate() {
                if l.split != v.split {
                    continue; // the scene never uses this pair
                }
                let rel = format!("images/v{vi:02}_l{li:02}.exr");
                let observed = scene.observed_image(vi, li)?;
                scene::images::write_exr_rgb(&tmp.join(&rel), w as usize, h as usize, &observed)?;
                frames.push(json!({
                    "file_path": rel,
                    "mask_path": mask_rel,
                    "fl_x": v.k[0][0], "fl_y": v.k[1][1], "cx": v.k[0][2], "cy": v.k[1][2],
                    "w": w, "h": h,
                    "transform_matrix": c2w,
                }));
                let light = match l.position {
                    Some(position) => CaptureLight::Point { position, intensity: l.intensity },
                    None => {
                        CaptureLight::Directional { direction: l.direction, intensity: l.intensity }
                    }
                };
                let entry = LightEntry { image: rel, light, split: Some(l.split) };
                lights.push(RawEntry::from(&entry));
            }
        }
        let transforms = json!({ "camera_model": "PINHOLE", "frames": frames });
        write(tmp, "transforms.json", &serde_json::to_string_pretty(&transforms).expect("json"))?;
        let lights = LightsFile { lights };
        write(tmp, "lights.json", &serde_json::to_string_pretty(&lights).expect("json"))?;
        let ply = scene::mesh_file::ply_bytes(&scene.mesh);
        std::fs::write(tmp.join("mesh.ply"), ply)
            .map_err(|e| Error::io(tmp.join("mesh.ply"), e))?;
        let toml = format!(
            "# Exported from the scene {} by dataset-capture.\nmesh = \"mesh.ply\"\n\n[images]\n\
             saturation = {:?}\n\n[check]\nmin_iou = 0.9\n",
            scene_dir.display(),
            m.config.settings.saturation,
        );
        write(tmp, crate::config::CAPTURE_FILE, &toml)
    })?;
    Ok(())
}

fn write(dir: &Path, name: &str, text: &str) -> Result<()> {
    let p = dir.join(name);
    std::fs::write(&p, text).map_err(|e| Error::io(&p, e))
}

/// The OpenGL camera-to-world matrix (4 x 4) of an OpenCV world-to-camera pose, in f64 such that
/// the importer's t = -R c gives `t` back to the last bit of f32: the centre is solved with the
/// exact inverse of the f32 rotation, not its transpose.
pub fn camera_to_world_gl(r: [[f32; 3]; 3], t: [f32; 3]) -> [[f64; 4]; 4] {
    let r = r.map(|row| row.map(f64::from));
    let t = t.map(f64::from);
    let inv = inverse3(&r);
    let c: [f64; 3] = std::array::from_fn(|i| -(0..3).map(|j| inv[i][j] * t[j]).sum::<f64>());
    // Camera-to-world rotation R^T in OpenCV axes; OpenGL flips the camera's y and z.
    let mut m = [[0.0; 4]; 4];
    for i in 0..3 {
        m[i][0] = r[0][i];
        m[i][1] = -r[1][i];
        m[i][2] = -r[2][i];
        m[i][3] = c[i];
    }
    m[3][3] = 1.0;
    m
}

fn inverse3(m: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let c = |i: usize, j: usize| {
        let (i1, i2) = ((i + 1) % 3, (i + 2) % 3);
        let (j1, j2) = ((j + 1) % 3, (j + 2) % 3);
        m[i1][j1] * m[i2][j2] - m[i1][j2] * m[i2][j1]
    };
    let det = m[0][0] * c(0, 0) + m[0][1] * c(0, 1) + m[0][2] * c(0, 2);
    std::array::from_fn(|i| std::array::from_fn(|j| c(j, i) / det))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cameras::world_to_camera;

    #[test]
    fn poses_survive_the_round_trip_to_the_last_bit() {
        let mut state = 7u64;
        let mut u = move || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 40) as f64 / (1u64 << 24) as f64
        };
        for _ in 0..200 {
            // A random rotation from a random unit quaternion, rounded to f32.
            let q: [f64; 4] = std::array::from_fn(|_| u() - 0.5);
            let n = q.iter().map(|x| x * x).sum::<f64>().sqrt();
            let [w, x, y, z] = q.map(|c| c / n);
            let r64 = [
                [1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - w * z), 2.0 * (x * z + w * y)],
                [2.0 * (x * y + w * z), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - w * x)],
                [2.0 * (x * z - w * y), 2.0 * (y * z + w * x), 1.0 - 2.0 * (x * x + y * y)],
            ];
            let r = r64.map(|row| row.map(|v| v as f32));
            let t: [f32; 3] = std::array::from_fn(|_| (6.0 * u() - 3.0) as f32);
            let m = camera_to_world_gl(r, t);
            let c2w = [
                [m[0][0], -m[0][1], -m[0][2]],
                [m[1][0], -m[1][1], -m[1][2]],
                [m[2][0], -m[2][1], -m[2][2]],
            ];
            let (r2, t2) = world_to_camera(&c2w, [m[0][3], m[1][3], m[2][3]]);
            assert_eq!(r2.map(|row| row.map(|v| v as f32)), r);
            assert_eq!(t2.map(|v| v as f32), t);
        }
    }
}
