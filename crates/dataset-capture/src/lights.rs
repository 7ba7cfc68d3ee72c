//! `lights.json`: the calibrated light of every image, directional or point
//! (docs/capture-format.md, "Lights").

use crate::error::{Error, Result};
use scene::manifest::Split;
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use std::path::Path;

/// The light of one image, in the capture's world frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CaptureLight {
    /// At infinity.
    Directional {
        /// From the object towards the light (normalised on import).
        direction: [f32; 3],
        /// Irradiance E, RGB, on a surface facing the light.
        intensity: [f32; 3],
    },
    /// At a point, with inverse-square falloff.
    Point {
        /// Its position.
        position: [f32; 3],
        /// Radiant intensity I, RGB: E = I / d^2 at distance d.
        intensity: [f32; 3],
    },
}

/// One entry of `lights.json`.
#[derive(Clone, Debug, PartialEq)]
pub struct LightEntry {
    /// The image, as the cameras file names it.
    pub image: String,
    /// The light.
    pub light: CaptureLight,
    /// Train or test (optional).
    pub split: Option<Split>,
}

/// An entry as written in the file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawEntry {
    /// The image.
    pub image: String,
    /// `directional` or `point`.
    #[serde(rename = "type")]
    pub kind: String,
    /// Directional lights: towards the light.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub direction: Option<[f32; 3]>,
    /// Point lights: the position.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub position: Option<[f32; 3]>,
    /// Irradiance (directional) or radiant intensity (point), RGB.
    pub intensity: [f32; 3],
    /// `train` or `test`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub split: Option<Split>,
}

impl From<&LightEntry> for RawEntry {
    fn from(e: &LightEntry) -> Self {
        let (kind, direction, position, intensity) = match e.light {
            CaptureLight::Directional { direction, intensity } => {
                ("directional", Some(direction), None, intensity)
            }
            CaptureLight::Point { position, intensity } => {
                ("point", None, Some(position), intensity)
            }
        };
        Self {
            image: e.image.clone(),
            kind: kind.into(),
            direction,
            position,
            intensity,
            split: e.split,
        }
    }
}

impl RawEntry {
    fn parse(self) -> std::result::Result<LightEntry, String> {
        let light = match (self.kind.as_str(), self.direction, self.position) {
            ("directional", Some(direction), None) => {
                if direction.iter().any(|x| !x.is_finite()) {
                    return Err(format!("direction {direction:?} is not finite"));
                }
                if direction.iter().all(|&x| x == 0.0) {
                    return Err("direction is the zero vector".into());
                }
                CaptureLight::Directional { direction, intensity: self.intensity }
            }
            ("point", None, Some(position)) => {
                if position.iter().any(|x| !x.is_finite()) {
                    return Err(format!("position {position:?} is not finite"));
                }
                CaptureLight::Point { position, intensity: self.intensity }
            }
            ("directional", _, _) => {
                return Err("a directional light has a `direction` (only)".into());
            }
            ("point", _, _) => return Err("a point light has a `position` (only)".into()),
            (other, _, _) => {
                return Err(format!("type `{other}`: expected `directional` or `point`"));
            }
        };
        if self.intensity.iter().any(|x| !x.is_finite() || *x < 0.0) {
            return Err(format!("intensity {:?} must be finite and >= 0", self.intensity));
        }
        Ok(LightEntry { image: self.image, light, split: self.split })
    }
}

/// The file.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightsFile {
    /// One entry per image.
    pub lights: Vec<RawEntry>,
}

/// The lights of a capture, by image name.
pub struct Lights {
    by_image: HashMap<String, LightEntry>,
}

impl Lights {
    /// Reads and checks `lights.json`: finite values, non-zero directions, non-negative
    /// intensities, one entry per image.
    pub fn read(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        let file: LightsFile =
            serde_json::from_str(&text).map_err(|e| Error::input(path, e.to_string()))?;
        let mut by_image = HashMap::new();
        for (i, raw) in file.lights.into_iter().enumerate() {
            let name = raw.image.clone();
            let fault = |f: String| Error::input(path, format!("light {i} (`{name}`): {f}"));
            let e = raw.parse().map_err(fault)?;
            if by_image.contains_key(&e.image) {
                return Err(fault("a second light for this image".into()));
            }
            by_image.insert(e.image.clone(), e);
        }
        Ok(Self { by_image })
    }

    /// The entry of `image`.
    pub fn get(&self, image: &str) -> Option<&LightEntry> {
        self.by_image.get(image)
    }

    /// Number of entries.
    pub fn len(&self) -> usize {
        self.by_image.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.by_image.is_empty()
    }

    /// The image names, sorted.
    pub fn images(&self) -> Vec<&str> {
        let mut v: Vec<&str> = self.by_image.keys().map(String::as_str).collect();
        v.sort_unstable();
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(json: &str) -> Result<Lights> {
        let dir = std::env::temp_dir().join(format!("lights-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join(format!("{:x}.json", xxh(json)));
        std::fs::write(&p, json).unwrap();
        let r = Lights::read(&p);
        std::fs::remove_file(&p).ok();
        r
    }

    fn xxh(s: &str) -> u64 {
        s.bytes().fold(0xcbf29ce484222325, |h, b| (h ^ b as u64).wrapping_mul(0x100000001b3))
    }

    #[test]
    fn both_kinds_parse() {
        let l = parse(
            r#"{"lights": [
              {"image": "a.exr", "type": "point", "position": [1, 2, 3], "intensity": [4, 4, 4]},
              {"image": "b.exr", "type": "directional", "direction": [0, 0, 1],
               "intensity": [1, 1, 1], "split": "test"}]}"#,
        )
        .unwrap();
        assert_eq!(l.len(), 2);
        assert!(matches!(l.get("a.exr").unwrap().light, CaptureLight::Point { .. }));
        assert_eq!(l.get("b.exr").unwrap().split, Some(Split::Test));
    }

    #[test]
    fn faults_name_the_light() {
        let e = |j: &str| parse(j).err().expect("an error").to_string();
        assert!(
            e(r#"{"lights": [{"image": "a", "type": "spot", "intensity": [1,1,1]}]}"#)
                .contains("spot")
        );
        assert!(e(r#"{"lights": [{"image": "a", "type": "directional", "direction": [0,0,0], "intensity": [1,1,1]}]}"#).contains("zero"));
        assert!(e(r#"{"lights": [{"image": "a", "type": "point", "position": [0,0,1], "intensity": [-1,1,1]}]}"#).contains("intensity"));
        let dup = r#"{"lights": [
            {"image": "a", "type": "point", "position": [0,0,1], "intensity": [1,1,1]},
            {"image": "a", "type": "point", "position": [0,0,2], "intensity": [1,1,1]}]}"#;
        assert!(e(dup).contains("second light"));
    }
}
