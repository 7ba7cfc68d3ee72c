//! `capture.toml`: where a capture's parts are and how to read its images (docs/capture-format.md).

use crate::error::{Error, Result};
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// The name of the file that describes a capture.
pub const CAPTURE_FILE: &str = "capture.toml";

/// How 8/16-bit PNG values become linear values (EXR is always linear).
#[derive(Clone, Copy, Debug, Default, PartialEq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Response {
    /// value / max code.
    #[default]
    Linear,
    /// The sRGB transfer function, inverted.
    Srgb,
    /// (value / max code) ^ gamma.
    Gamma,
}

/// `[images]`.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ImageSettings {
    /// PNG response.
    pub response: Response,
    /// The exponent of [`Response::Gamma`].
    pub gamma: f32,
    /// Radiance = scale x linearised value.
    pub scale: f32,
    /// A channel at or above this linearised value (before `scale`) is saturated; default: the
    /// maximum code of a PNG, none for EXR.
    pub saturation: Option<f32>,
}

impl Default for ImageSettings {
    fn default() -> Self {
        Self { response: Response::Linear, gamma: 2.2, scale: 1.0, saturation: None }
    }
}

/// `[check]`.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CheckSettings {
    /// The smallest mask/silhouette IoU a view may have.
    pub min_iou: f64,
}

impl Default for CheckSettings {
    fn default() -> Self {
        Self { min_iou: 0.9 }
    }
}

/// The contents of `capture.toml`, paths resolved against its folder.
#[derive(Clone, Debug, PartialEq)]
pub struct CaptureConfig {
    /// The folder holding `capture.toml`.
    pub root: PathBuf,
    /// A `transforms.json` file or a COLMAP text model folder.
    pub cameras: PathBuf,
    /// The lights file.
    pub lights: PathBuf,
    /// The mesh.
    pub mesh: PathBuf,
    /// COLMAP: the folder its image names are relative to.
    pub images: PathBuf,
    /// COLMAP: the folder of `<image name>.png` masks.
    pub masks: Option<PathBuf>,
    /// Image decoding.
    pub image: ImageSettings,
    /// The alignment check.
    pub check: CheckSettings,
    /// Without per-image splits: every n-th view is a test view.
    pub test_every: usize,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Raw {
    #[serde(default = "default_cameras")]
    cameras: PathBuf,
    #[serde(default = "default_lights")]
    lights: PathBuf,
    mesh: PathBuf,
    #[serde(default = "default_image_dir")]
    image_dir: PathBuf,
    #[serde(default)]
    mask_dir: Option<PathBuf>,
    #[serde(default)]
    images: ImageSettings,
    #[serde(default)]
    check: CheckSettings,
    #[serde(default = "default_test_every")]
    test_every: usize,
}

fn default_cameras() -> PathBuf {
    "transforms.json".into()
}
fn default_lights() -> PathBuf {
    "lights.json".into()
}
fn default_image_dir() -> PathBuf {
    "images".into()
}
fn default_test_every() -> usize {
    5
}

impl CaptureConfig {
    /// Reads `dir/capture.toml`.
    pub fn read(dir: &Path) -> Result<Self> {
        let path = dir.join(CAPTURE_FILE);
        let text = std::fs::read_to_string(&path).map_err(|e| Error::io(&path, e))?;
        Self::parse(dir, &text).map_err(|fault| Error::input(&path, fault))
    }

    /// Parses the text of `capture.toml` of the capture in `dir`.
    pub fn parse(dir: &Path, text: &str) -> std::result::Result<Self, String> {
        let raw: Raw = toml::from_str(text).map_err(|e| e.to_string().trim().to_string())?;
        let image = raw.images;
        if !(image.scale.is_finite() && image.scale > 0.0) {
            return Err(format!("[images] scale = {} must be positive and finite", image.scale));
        }
        if !(image.gamma.is_finite() && image.gamma > 0.0) {
            return Err(format!("[images] gamma = {} must be positive and finite", image.gamma));
        }
        if let Some(s) = image.saturation
            && !(s.is_finite() && s > 0.0)
        {
            return Err(format!("[images] saturation = {s} must be positive and finite"));
        }
        if !(0.0..=1.0).contains(&raw.check.min_iou) {
            return Err(format!("[check] min_iou = {} must be in [0, 1]", raw.check.min_iou));
        }
        if raw.test_every == 0 {
            return Err("test_every must be at least 1".into());
        }
        Ok(Self {
            root: dir.to_path_buf(),
            cameras: dir.join(raw.cameras),
            lights: dir.join(raw.lights),
            mesh: dir.join(raw.mesh),
            images: dir.join(raw.image_dir),
            masks: raw.mask_dir.map(|m| dir.join(m)),
            image,
            check: raw.check,
            test_every: raw.test_every,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_and_tables() {
        let c = CaptureConfig::parse(Path::new("/c"), "mesh = \"m.ply\"\n").unwrap();
        assert_eq!(c.cameras, Path::new("/c/transforms.json"));
        assert_eq!(c.image, ImageSettings::default());
        assert_eq!(c.check.min_iou, 0.9);
        let c = CaptureConfig::parse(
            Path::new("/c"),
            "mesh = \"m.ply\"\n[images]\nresponse = \"srgb\"\nscale = 2.0\n[check]\nmin_iou = 0.5\n",
        )
        .unwrap();
        assert_eq!(c.image.response, Response::Srgb);
        assert_eq!(c.image.scale, 2.0);
        assert_eq!(c.check.min_iou, 0.5);
    }

    #[test]
    fn bad_keys_and_values_are_named() {
        let bad = |t: &str| CaptureConfig::parse(Path::new("/c"), t).unwrap_err();
        assert!(bad("mesh = \"m\"\ncolour = 1\n").contains("colour"), "{}", bad("colour = 1"));
        assert!(bad("cameras = \"t.json\"\n").contains("mesh"));
        assert!(bad("mesh = \"m\"\n[images]\nscale = -1.0\n").contains("scale"));
        assert!(bad("mesh = \"m\"\n[images]\nresponse = \"log\"\n").contains("log"));
        assert!(bad("mesh = \"m\"\n[check]\nmin_iou = 2.0\n").contains("min_iou"));
        assert!(bad("mesh = \"m\"\ntest_every = 0\n").contains("test_every"));
    }
}
