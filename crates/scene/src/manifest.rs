//! The manifest of a scene directory: versioned, self-describing, and self-checking.
//!
//! `manifest.json` lists the configuration that produced the scene, the cameras (OpenCV K, R, t)
//! and lights of every view with their train/test split, every data file with its size and xxh3
//! hash, and summary statistics. Its own `checksum` (xxh3-64 of the manifest serialised with the
//! checksum field empty) makes any edit detectable; every listed file is checked on open.

use crate::config::SceneConfig;
use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Format name in every manifest.
pub const FORMAT: &str = "neural-brdf-scene";
/// Current format version. 2: semi-synthetic scenes carry the noise-free test renders
/// (`clean/`), and their radiance is formed in f32 by [`shade`](crate::shading::shade).
pub const VERSION: u32 = 2;
/// The manifest's file name inside a scene directory.
pub const MANIFEST_FILE: &str = "manifest.json";

/// Which part of the data a view or light belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Split {
    /// Used for fitting.
    Train,
    /// Used for evaluation.
    Test,
}

/// One light of a view: directional, or a point light when `position` is set.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightInfo {
    /// Unit world direction from the surface towards the light. For a point light, the
    /// direction from the scene's centre towards it (for display; shading uses the position).
    pub direction: [f32; 3],
    /// Directional light: irradiance E, RGB. Point light: radiant intensity I, RGB, so that a
    /// point at distance d receives E = I / d^2 ([`crate::shading::light_at`]).
    pub intensity: [f32; 3],
    /// Split of this light within its view.
    pub split: Split,
    /// For captured scenes: the light's 1-based image number in the source capture (absent in
    /// generated scenes, whose manifests are unchanged by this field).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub source_index: Option<u32>,
    /// A point light's world position (absent for a directional light, and in every manifest
    /// written before point lights existed, which are unchanged by this field).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub position: Option<[f32; 3]>,
}

impl LightInfo {
    /// The light as ray casting needs it.
    pub fn source(&self) -> raycast_precompute::Light {
        match self.position {
            Some(p) => raycast_precompute::Light::Point(glam::Vec3::from_array(p)),
            None => raycast_precompute::Light::Directional(glam::Vec3::from_array(self.direction)),
        }
    }
}

/// One camera view.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ViewInfo {
    /// Split of the view.
    pub split: Split,
    /// Intrinsics K, rows.
    pub k: [[f32; 3]; 3],
    /// Rotation R (world to camera), rows.
    pub r: [[f32; 3]; 3],
    /// Translation t (x_cam = R x_world + t).
    pub t: [f32; 3],
    /// The lights of this view.
    pub lights: Vec<LightInfo>,
}

/// A data file of the scene.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FileEntry {
    /// Path relative to the scene directory.
    pub path: String,
    /// Size in bytes.
    pub bytes: u64,
    /// xxh3-64 of the contents, hexadecimal.
    pub xxh3: String,
}

impl FileEntry {
    /// The entry of a file at `path` (relative) with these contents.
    pub fn of(path: String, bytes: &[u8]) -> Self {
        Self { path, bytes: bytes.len() as u64, xxh3: hash_hex(bytes) }
    }
}

/// Counts over all (foreground pixel, light) samples.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneStats {
    /// Foreground pixels over all views.
    pub foreground_pixels: u64,
    /// Lit samples (BRDF evaluated).
    pub lit_samples: u64,
    /// Shadowed samples.
    pub shadowed_samples: u64,
    /// Samples whose light or view is below the shading surface.
    pub back_facing_samples: u64,
    /// Samples with a saturated (clipped) channel.
    pub saturated_samples: u64,
    /// Lit samples whose ground-truth BRDF is invalid (negative MERL entry).
    pub invalid_gt_samples: u64,
    /// saturated / (lit + shadowed + back-facing).
    pub saturated_fraction: f64,
}

impl SceneStats {
    /// The sample counts of one flags image ([`flag`](crate::flag) bits per pixel); an invalid
    /// ground truth is a lit sample without `GT_VALID`.
    pub fn count_flags(flags: &[u8]) -> Self {
        use crate::flag::{BACK_FACING, GT_VALID, LIT, SATURATED, SHADOWED};
        let mut st = Self::default();
        for &f in flags {
            st.lit_samples += u64::from(f & LIT != 0);
            st.shadowed_samples += u64::from(f & SHADOWED != 0);
            st.back_facing_samples += u64::from(f & BACK_FACING != 0);
            st.saturated_samples += u64::from(f & SATURATED != 0);
            st.invalid_gt_samples += u64::from(f & LIT != 0 && f & GT_VALID == 0);
        }
        st
    }

    /// Adds the sample counts of `other` (not its pixels or fraction).
    pub fn add_counts(&mut self, other: &Self) {
        self.lit_samples += other.lit_samples;
        self.shadowed_samples += other.shadowed_samples;
        self.back_facing_samples += other.back_facing_samples;
        self.saturated_samples += other.saturated_samples;
        self.invalid_gt_samples += other.invalid_gt_samples;
    }

    /// Sets `saturated_fraction` from the counts, rounded to 1e-12 so that it survives the
    /// manifest's JSON round trip bit for bit: serde_json's default float parser is exact only
    /// for decimals of at most 15 significant digits, and the manifest's checksum is taken over
    /// the re-serialised values.
    pub fn update_saturated_fraction(&mut self) {
        let all = self.lit_samples + self.shadowed_samples + self.back_facing_samples;
        let f = self.saturated_samples as f64 / all.max(1) as f64;
        self.saturated_fraction = (f * 1e12).round() / 1e12;
    }
}

/// The manifest of a scene directory.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    /// Always [`FORMAT`].
    pub format: String,
    /// Format version, [`VERSION`] when written by this crate.
    pub version: u32,
    /// The generator and its version.
    pub generator: String,
    /// Provenance label of the data, for example "MERL-derived (NBRDF)".
    pub label: String,
    /// The configuration that produced the scene.
    pub config: SceneConfig,
    /// The normalised, cleaned mesh inside the directory (binary PLY).
    pub mesh_file: String,
    /// Its vertex count.
    pub mesh_vertices: usize,
    /// Its triangle count.
    pub mesh_triangles: usize,
    /// The views.
    pub views: Vec<ViewInfo>,
    /// Every data file.
    pub files: Vec<FileEntry>,
    /// Summary statistics.
    pub stats: SceneStats,
    /// xxh3-64 of this manifest serialised with `checksum` empty, hexadecimal.
    pub checksum: String,
}

/// xxh3-64 of a byte string, as 16 hex digits.
pub fn hash_hex(bytes: &[u8]) -> String {
    format!("{:016x}", xxhash_rust::xxh3::xxh3_64(bytes))
}

impl Manifest {
    fn body_checksum(&self) -> String {
        let mut unsigned = self.clone();
        unsigned.checksum.clear();
        hash_hex(serde_json::to_string(&unsigned).expect("manifest serialises").as_bytes())
    }

    /// Serialises the manifest with its checksum filled in.
    pub fn to_json(&mut self) -> String {
        self.checksum = self.body_checksum();
        serde_json::to_string_pretty(self).expect("manifest serialises")
    }

    /// Reads and checks a manifest: format, version and its own checksum.
    pub fn read(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        let fault = |fault: String| Error::Dataset { path: path.into(), fault };
        let m: Manifest = serde_json::from_str(&text).map_err(|e| fault(e.to_string()))?;
        if m.format != FORMAT {
            return Err(fault(format!("format `{}`, expected `{FORMAT}`", m.format)));
        }
        if m.version != VERSION {
            return Err(fault(format!(
                "format version {}, this build reads {VERSION} (version 2 added the noise-free \
                 test renders the noise ceiling needs): regenerate the scene (`cargo xtask \
                 generate-scenes`; `reproduce-tables` does it by itself) or re-import the \
                 capture (`cargo xtask import-diligent`)",
                m.version
            )));
        }
        if m.checksum != m.body_checksum() {
            return Err(fault("checksum mismatch: the manifest was edited or damaged".into()));
        }
        Ok(m)
    }

    /// Checks every listed file (size, then hash) inside `dir`.
    pub fn verify_files(&self, dir: &Path) -> Result<()> {
        use rayon::prelude::*;
        self.files.par_iter().try_for_each(|f| {
            let path = dir.join(&f.path);
            let fault = |fault: String| Error::Dataset { path: path.clone(), fault };
            let bytes = std::fs::read(&path).map_err(|e| Error::io(&path, e))?;
            if bytes.len() as u64 != f.bytes {
                return Err(fault(format!("{} bytes, the manifest says {}", bytes.len(), f.bytes)));
            }
            if hash_hex(&bytes) != f.xxh3 {
                return Err(fault("contents differ from the manifest's hash".into()));
            }
            Ok(())
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn saturated_fraction_survives_the_json_round_trip() {
        for (sat, lit) in [(298, 662_000), (1, 3), (7, 1_000_000_007), (0, 0)] {
            let mut st =
                SceneStats { saturated_samples: sat, lit_samples: lit, ..Default::default() };
            st.update_saturated_fraction();
            let back: SceneStats =
                serde_json::from_str(&serde_json::to_string(&st).unwrap()).unwrap();
            assert_eq!(
                back.saturated_fraction.to_bits(),
                st.saturated_fraction.to_bits(),
                "{sat}/{lit}"
            );
        }
    }
}
