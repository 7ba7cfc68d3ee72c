//! What a scene is made of: mesh, material, seed and settings (spec section 6 and the decisions
//! table). Every value is configurable; the defaults are the paper's semi-synthetic setup.
//! Captured scenes record the same description with the capture's values.

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// How a tabulated (MERL) BRDF is sampled between its bins.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Lookup {
    /// The reference reader's rule: the bin containing the angles, no interpolation.
    #[default]
    NearestLower,
    /// Trilinear interpolation between bin lower edges (periodic in phi_d).
    Trilinear,
}

/// The material rendered onto the mesh.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum MaterialSpec {
    /// A catalogue material by MERL name (a real MERL binary from `merl_dir` when present,
    /// else the shipped NBRDF network).
    Merl {
        /// The MERL name, for example "blue-acrylic".
        name: String,
    },
    /// A Lambertian material (for tests and sanity checks).
    Lambert {
        /// Albedo, linear RGB in [0, 1].
        albedo: [f32; 3],
    },
    /// A real capture imported from a benchmark (for example by `dataset-diligent`): the
    /// material is unknown, there is no ground-truth BRDF, and the scene cannot be generated.
    Captured {
        /// The benchmark, for example "DiLiGenT" or "DiLiGenT-MV".
        benchmark: String,
        /// The object, for example "ball".
        object: String,
    },
}

/// Rendering settings of a scene.
///
/// | key | default | meaning |
/// | --- | --- | --- |
/// | `width`, `height` | 512 | image size in pixels |
/// | `views` | 20 | cameras on a sphere around the normalised mesh |
/// | `train_views` | 10 | of which used for training (chosen by the seed); the rest test |
/// | `lights_per_view` | 42 | directional lights per view, within 60 degrees of the camera |
/// | `train_lights` | 30 | the first lights of a view are training lights, the rest test |
/// | `fov_y_deg` | 40 | vertical field of view |
/// | `camera_distance` | 3 | camera distance from the origin (mesh in the unit sphere) |
/// | `light_intensity` | (pi, pi, pi) | irradiance E of every light, RGB (a white Lambertian at normal incidence renders 1) |
/// | `noise_sigma` | 1e-3 | Gaussian noise per channel, absolute, on linear values |
/// | `saturation` | 2.0 | observed values are clipped here; such pixels are flagged saturated |
/// | `lookup` | nearest-lower | MERL lookup rule |
/// | `shadow_bias_relative` | 1e-4 | shadow-ray offset as a fraction of the mesh diagonal |
/// | `up_axis` | y | the mesh's up axis; the mesh is rotated so that it points to +z, the orbit's up |
/// | `point_light_distance` | none | point lights instead of directional ones: each light at this distance from the origin along its rig direction, with radiant intensity `light_intensity` x distance^2 (the irradiance at the origin is `light_intensity`) |
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SceneSettings {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Number of views.
    pub views: usize,
    /// Number of training views.
    pub train_views: usize,
    /// Lights per view.
    pub lights_per_view: usize,
    /// Training lights per view.
    pub train_lights: usize,
    /// Vertical field of view, degrees.
    pub fov_y_deg: f32,
    /// Camera distance from the origin.
    pub camera_distance: f32,
    /// Light irradiance, RGB.
    pub light_intensity: [f32; 3],
    /// Noise standard deviation.
    pub noise_sigma: f32,
    /// Saturation (clip) level.
    pub saturation: f32,
    /// MERL lookup rule.
    pub lookup: Lookup,
    /// Shadow bias relative to the mesh diagonal.
    pub shadow_bias_relative: f32,
    /// The mesh's up axis (the common test meshes are y-up).
    pub up_axis: UpAxis,
    /// Point lights at this distance from the origin instead of directional lights (absent:
    /// directional, and absent from the configurations written before it existed).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub point_light_distance: Option<f32>,
}

/// Which mesh axis points up.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum UpAxis {
    /// +y up (OBJ convention of most test meshes): rotated by +90 degrees about x.
    #[default]
    Y,
    /// +z up: used as is.
    Z,
}

impl SceneSettings {
    /// The defaults with square `size` x `size` images, `views` cameras (half of them train)
    /// and `lights` lights per view (train lights in the default 30 : 42 proportion).
    pub fn with_counts(size: u32, views: usize, lights: usize) -> Self {
        let d = Self::default();
        Self {
            width: size,
            height: size,
            views,
            train_views: views / 2,
            lights_per_view: lights,
            train_lights: (lights * d.train_lights / d.lights_per_view.max(1)).max(1),
            ..d
        }
    }
}

impl Default for SceneSettings {
    fn default() -> Self {
        let pi = std::f32::consts::PI;
        Self {
            width: 512,
            height: 512,
            views: 20,
            train_views: 10,
            lights_per_view: 42,
            train_lights: 30,
            fov_y_deg: 40.0,
            camera_distance: 3.0,
            light_intensity: [pi; 3],
            noise_sigma: 1e-3,
            saturation: 2.0,
            lookup: Lookup::NearestLower,
            shadow_bias_relative: 1e-4,
            up_axis: UpAxis::Y,
            point_light_distance: None,
        }
    }
}

/// A complete scene description: the input of the generator.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneConfig {
    /// The mesh file (OBJ, PLY, glTF/GLB); it is cleaned and normalised into the unit sphere.
    pub mesh: PathBuf,
    /// The material.
    pub material: MaterialSpec,
    /// Seed of every random choice (view split, lights, noise).
    pub seed: u64,
    /// Rendering settings.
    #[serde(default)]
    pub settings: SceneSettings,
    /// Directory with real MERL binaries (`<name>.binary`), which take precedence.
    #[serde(default)]
    pub merl_dir: Option<PathBuf>,
}

impl SceneConfig {
    /// Parses a JSON configuration; unknown keys are errors naming the key.
    pub fn from_json(text: &str) -> Result<Self> {
        let c: Self = serde_json::from_str(text)
            .map_err(|e| Error::Config { key: "<document>".into(), fault: e.to_string() })?;
        c.validate()?;
        Ok(c)
    }

    /// Checks every value; the error names the key. Whether a MERL material name exists is the
    /// generator's question (dataset-merl's catalogue), not the format's.
    pub fn validate(&self) -> Result<()> {
        let s = &self.settings;
        let bad = |key: &str, fault: String| Err(Error::Config { key: key.into(), fault });
        if s.width == 0 || s.height == 0 || s.width > 16384 || s.height > 16384 {
            return bad(
                "settings.width/height",
                format!("{} x {} is not in 1..=16384", s.width, s.height),
            );
        }
        if s.views == 0 || s.train_views > s.views {
            return bad("settings.train_views", format!("{} of {} views", s.train_views, s.views));
        }
        if s.lights_per_view == 0 || s.train_lights > s.lights_per_view {
            return bad(
                "settings.train_lights",
                format!("{} of {} lights", s.train_lights, s.lights_per_view),
            );
        }
        if !(s.fov_y_deg > 0.0 && s.fov_y_deg < 179.0) {
            return bad("settings.fov_y_deg", format!("{} is not in (0, 179)", s.fov_y_deg));
        }
        if !(s.camera_distance > 1.0 && s.camera_distance.is_finite()) {
            return bad(
                "settings.camera_distance",
                format!("{} must exceed 1 (the mesh's radius)", s.camera_distance),
            );
        }
        if s.light_intensity.iter().any(|e| !(e.is_finite() && *e >= 0.0)) {
            return bad(
                "settings.light_intensity",
                format!("{:?} must be finite and >= 0", s.light_intensity),
            );
        }
        if !(s.noise_sigma >= 0.0 && s.noise_sigma.is_finite()) {
            return bad(
                "settings.noise_sigma",
                format!("{} must be finite and >= 0", s.noise_sigma),
            );
        }
        if s.saturation.is_nan() || s.saturation <= 0.0 {
            return bad("settings.saturation", format!("{} must be > 0", s.saturation));
        }
        if !(s.shadow_bias_relative >= 0.0 && s.shadow_bias_relative < 0.1) {
            return bad(
                "settings.shadow_bias_relative",
                format!("{} is not in [0, 0.1)", s.shadow_bias_relative),
            );
        }
        if let Some(d) = s.point_light_distance
            && !(d > 1.0 && d.is_finite())
        {
            return bad(
                "settings.point_light_distance",
                format!("{d} must exceed 1 (the mesh's radius) and be finite"),
            );
        }
        if let MaterialSpec::Lambert { albedo } = &self.material
            && albedo.iter().any(|a| !(0.0..=1.0).contains(a))
        {
            return bad("material.albedo", format!("{albedo:?} is not in [0, 1]"));
        }
        if let MaterialSpec::Merl { name } = &self.material
            && name.trim().is_empty()
        {
            return bad("material.name", "is empty".into());
        }
        Ok(())
    }
}
