//! One photometric-stereo capture directory as DiLiGenT lays it out (the single-view
//! `pmsData/<obj>PNG/` and every DiLiGenT-MV `view_XX/`): images `001.png ...` (16-bit RGB, one
//! calibrated directional light each; names from `filenames.txt` when present),
//! `light_directions.txt` and `light_intensities.txt` (one row per image, three numbers each) and
//! `mask.png`.
//!
//! **Axes.** DiLiGenT gives light directions (and normals) in its camera frame: x right, y up,
//! z towards the camera, so lights in front of the object have z > 0. The OpenCV camera frame
//! used by `raycast-precompute` has y down and z forward, hence [`diligent_to_opencv`]:
//! (x, y, z) -> (x, -y, -z). (Checked on the ball: the ground-truth normal at the top of the
//! mask has y > 0, and n . l correlates with the observed intensity.)
//!
//! **Radiance.** A raw 16-bit value divided by 65535 and by the light's intensity (per channel)
//! is the radiance for unit irradiance, as the benchmark's scripts do; [`Capture::radiance`].
//!
//! Every check names the file and the fault: missing images, light files whose row counts differ
//! from each other or from the images, intensities that are zero, negative or not finite,
//! directions that are not unit vectors, masks or images of another size, 8-bit or damaged PNGs.

use crate::error::{Error, Result};
use std::path::{Path, PathBuf};
use stdx::Limits;

/// Light directions file name.
pub const LIGHT_DIRECTIONS: &str = "light_directions.txt";
/// Light intensities file name.
pub const LIGHT_INTENSITIES: &str = "light_intensities.txt";
/// Mask file name.
pub const MASK: &str = "mask.png";
/// Optional list of image names, one per light.
pub const FILENAMES: &str = "filenames.txt";

/// Largest deviation of a light direction's length from 1 that is accepted (the files round to
/// four decimals); the direction is renormalised.
const UNIT_TOLERANCE: f64 = 0.01;

/// DiLiGenT's camera frame (x right, y up, z towards the camera) to OpenCV's (x right, y down,
/// z forward).
pub fn diligent_to_opencv(d: [f64; 3]) -> [f64; 3] {
    [d[0], -d[1], -d[2]]
}

/// A checked capture directory; images are decoded on demand.
#[derive(Clone, Debug)]
pub struct Capture {
    /// The directory.
    pub dir: PathBuf,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Foreground mask, row-major.
    pub mask: Vec<bool>,
    /// Image file of each light.
    pub images: Vec<PathBuf>,
    /// Unit light directions in DiLiGenT's camera frame (see the module documentation).
    pub directions: Vec<[f64; 3]>,
    /// Light intensities, RGB, each finite and > 0.
    pub intensities: Vec<[f64; 3]>,
    /// What the image reader accepts: the caller's limits, with no image larger than the mask.
    pub limits: Limits,
}

/// Reads a text file of rows of three numbers (blank lines ignored).
fn read_rows(path: &Path) -> Result<Vec<[f64; 3]>> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    let mut rows = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let fields: Vec<&str> =
            line.split(|c: char| c.is_whitespace() || c == ',').filter(|f| !f.is_empty()).collect();
        if fields.is_empty() {
            continue;
        }
        let bad =
            || Error::input(path, format!("line {}: expected three numbers, got `{line}`", i + 1));
        if fields.len() != 3 {
            return Err(bad());
        }
        let mut row = [0.0; 3];
        for (r, f) in row.iter_mut().zip(&fields) {
            *r = f.parse().map_err(|_| bad())?;
        }
        rows.push(row);
    }
    Ok(rows)
}

fn image_err(path: &Path, e: impl std::fmt::Display) -> Error {
    Error::input(path, format!("cannot decode image: {e}"))
}

/// Decodes a 16-bit RGB (or RGBA, alpha dropped, or gray) PNG within `limits`: (width,
/// height, pixels).
pub fn read_png16(path: &Path, limits: &Limits) -> Result<(u32, u32, Vec<[u16; 3]>)> {
    if !path.is_file() {
        return Err(Error::input(path, "image is missing"));
    }
    let img = scene::images::decode_within(path, limits).map_err(|e| image_err(path, e))?;
    let (w, h) = (img.width(), img.height());
    let px: Vec<[u16; 3]> = match img {
        image::DynamicImage::ImageRgb16(b) => b.pixels().map(|p| p.0).collect(),
        image::DynamicImage::ImageRgba16(b) => {
            b.pixels().map(|p| [p.0[0], p.0[1], p.0[2]]).collect()
        }
        image::DynamicImage::ImageLuma16(b) => b.pixels().map(|p| [p.0[0]; 3]).collect(),
        other => {
            return Err(Error::input(
                path,
                format!("colour type {:?}, expected 16-bit RGB", other.color()),
            ));
        }
    };
    Ok((w, h, px))
}

/// Decodes a mask PNG of any colour type within `limits`: foreground where any channel is at
/// least half scale.
pub fn read_mask(path: &Path, limits: &Limits) -> Result<(u32, u32, Vec<bool>)> {
    if !path.is_file() {
        return Err(Error::input(path, "mask is missing"));
    }
    let img = scene::images::decode_within(path, limits).map_err(|e| image_err(path, e))?;
    let img = img.into_rgb8();
    let (w, h) = img.dimensions();
    Ok((w, h, img.pixels().map(|p| p.0.iter().any(|&c| c >= 128)).collect()))
}

/// Per light: a direction or an RGB intensity.
type PerLight = Vec<[f64; 3]>;

/// The light directions (unit, checked) and intensities (finite, positive) of a capture
/// directory, one per image.
fn read_lights(dir: &Path) -> Result<(PerLight, PerLight)> {
    let dir_path = dir.join(LIGHT_DIRECTIONS);
    let int_path = dir.join(LIGHT_INTENSITIES);
    let raw_dirs = read_rows(&dir_path)?;
    let intensities = read_rows(&int_path)?;
    if raw_dirs.is_empty() {
        return Err(Error::input(&dir_path, "no light directions"));
    }
    if raw_dirs.len() != intensities.len() {
        return Err(Error::input(
            &int_path,
            format!(
                "{} light intensities, but {} has {} directions",
                intensities.len(),
                LIGHT_DIRECTIONS,
                raw_dirs.len()
            ),
        ));
    }
    for (i, e) in intensities.iter().enumerate() {
        if e.iter().any(|c| !(c.is_finite() && *c > 0.0)) {
            return Err(Error::input(
                &int_path,
                format!("light {}: intensity {e:?} must be finite and > 0 per channel", i + 1),
            ));
        }
    }
    let mut directions = Vec::with_capacity(raw_dirs.len());
    for (i, d) in raw_dirs.iter().enumerate() {
        let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        if !(n.is_finite() && (n - 1.0).abs() <= UNIT_TOLERANCE) {
            return Err(Error::input(
                &dir_path,
                format!("light {}: direction {d:?} is not a unit vector (length {n})", i + 1),
            ));
        }
        directions.push(d.map(|c| c / n));
    }
    Ok((directions, intensities))
}

/// The image files of `count` lights: from the file-name list when there is one, else
/// `001.png`, `002.png`, ...
fn image_paths(dir: &Path, count: usize) -> Result<Vec<PathBuf>> {
    let names_path = dir.join(FILENAMES);
    let images: Vec<PathBuf> = if names_path.is_file() {
        let text = std::fs::read_to_string(&names_path).map_err(|e| Error::io(&names_path, e))?;
        text.lines().map(str::trim).filter(|l| !l.is_empty()).map(|l| dir.join(l)).collect()
    } else {
        (1..=count).map(|i| dir.join(format!("{i:03}.png"))).collect()
    };
    if images.len() != count {
        return Err(Error::input(
            &names_path,
            format!("{} image names, but {count} light directions", images.len()),
        ));
    }
    Ok(images)
}

/// Checks that every image exists and has the mask's size (the first image's mismatch is
/// reported against the mask).
fn check_image_sizes(images: &[PathBuf], mask_path: &Path, width: u32, height: u32) -> Result<()> {
    let first = &images[0];
    if first.is_file() {
        let (w, h) = image::image_dimensions(first).map_err(|e| image_err(first, e))?;
        if (w, h) != (width, height) {
            return Err(Error::input(
                mask_path,
                format!("{width} x {height} pixels, but the images are {w} x {h}"),
            ));
        }
    }
    for img in images {
        if !img.is_file() {
            return Err(Error::input(img, "image is missing"));
        }
        let (w, h) = image::image_dimensions(img).map_err(|e| image_err(img, e))?;
        if (w, h) != (width, height) {
            return Err(Error::input(
                img,
                format!("{w} x {h} pixels, but {MASK} is {width} x {height}"),
            ));
        }
    }
    Ok(())
}

impl Capture {
    /// Opens and checks a capture directory (light files, mask, and every image's header),
    /// whose images are read within `limits`.
    pub fn open(dir: &Path, limits: &Limits) -> Result<Self> {
        if !dir.is_dir() {
            return Err(Error::input(dir, "capture directory is missing"));
        }
        let (directions, intensities) = read_lights(dir)?;
        let images = image_paths(dir, directions.len())?;
        let mask_path = dir.join(MASK);
        let (width, height, mask) = read_mask(&mask_path, limits)?;
        if !mask.iter().any(|&m| m) {
            return Err(Error::input(&mask_path, "the mask is empty"));
        }
        check_image_sizes(&images, &mask_path, width, height)?;
        let limits = Limits { max_image_pixels: u64::from(width) * u64::from(height), ..*limits };
        Ok(Self { dir: dir.into(), width, height, mask, images, directions, intensities, limits })
    }

    /// Number of lights (images).
    pub fn len(&self) -> usize {
        self.images.len()
    }

    /// Whether there are no lights (never true for an opened capture).
    pub fn is_empty(&self) -> bool {
        self.images.is_empty()
    }

    /// The raw 16-bit image of light `i` (0-based), row-major.
    pub fn raw_image(&self, i: usize) -> Result<Vec<[u16; 3]>> {
        let path = &self.images[i];
        let (w, h, px) = read_png16(path, &self.limits)?;
        if (w, h) != (self.width, self.height) {
            return Err(Error::input(
                path,
                format!("{w} x {h} pixels, but {MASK} is {} x {}", self.width, self.height),
            ));
        }
        Ok(px)
    }

    /// Radiance for unit irradiance of a raw value under light `i`: raw / 65535 / intensity.
    pub fn radiance(&self, i: usize, raw: [u16; 3]) -> [f32; 3] {
        let e = self.intensities[i];
        [0, 1, 2].map(|c| (raw[c] as f64 / 65535.0 / e[c]) as f32)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_parse_with_spaces_or_commas_and_name_the_bad_line() {
        let dir =
            std::env::temp_dir().join(format!("dataset-diligent-rows-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("rows.txt");
        std::fs::write(&p, "1 2 3\n\n4,5,6\n").unwrap();
        assert_eq!(read_rows(&p).unwrap(), [[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]);
        std::fs::write(&p, "1 2 3\n4 5\n").unwrap();
        let e = read_rows(&p).unwrap_err().to_string();
        assert!(e.contains("rows.txt") && e.contains("line 2"), "{e}");
        std::fs::write(&p, "1 2 x\n").unwrap();
        assert!(read_rows(&p).unwrap_err().to_string().contains("line 1"));
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn diligent_axes_flip_y_and_z() {
        // A light in front of the object, above the camera, is up (-y) and towards the camera
        // (-z) in OpenCV's frame.
        assert_eq!(diligent_to_opencv([0.1, 0.5, 0.8]), [0.1, -0.5, -0.8]);
    }
}
