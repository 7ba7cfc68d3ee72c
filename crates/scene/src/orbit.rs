//! The camera rig of generated scenes: `views` cameras on a Fibonacci orbit around the mesh
//! (normalised into the unit sphere), at `camera_distance`, looking at the origin with +z up,
//! each with `lights_per_view` directional lights within 60 degrees of its direction, drawn from
//! the scene's seed (spec section 6); with `point_light_distance`, point lights at that distance
//! along the same directions. The rig is part of every generated scene's bytes (through
//! the cameras and light directions in its manifest), so it changes only with the format version.

use crate::config::SceneSettings;
use crate::error::Result;
use raycast_precompute::{Light, View};

/// The views (cameras and light directions) of a generated scene with these settings and seed.
pub fn orbit_views(settings: &SceneSettings, seed: u64) -> Result<Vec<View>> {
    let s = settings;
    let mut views = raycast_precompute::rig::orbit_views(
        s.views,
        s.lights_per_view,
        (s.width, s.height),
        s.camera_distance,
        s.fov_y_deg,
        seed,
    )?;
    if let Some(distance) = s.point_light_distance {
        for v in &mut views {
            for l in &mut v.lights {
                if let Light::Directional(d) = *l {
                    *l = Light::Point(distance * d);
                }
            }
        }
    }
    Ok(views)
}
