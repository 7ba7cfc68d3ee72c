//! The camera rig of generated scenes: `views` cameras on a Fibonacci orbit around the mesh
//! (normalised into the unit sphere), at `camera_distance`, looking at the origin with +z up,
//! each with `lights_per_view` directional lights within 60 degrees of its direction, drawn from
//! the scene's seed (spec section 6). The rig is part of every generated scene's bytes (through
//! the cameras and light directions in its manifest), so it changes only with the format version.

use crate::config::SceneSettings;
use crate::error::Result;
use raycast_precompute::View;

/// The views (cameras and light directions) of a generated scene with these settings and seed.
pub fn orbit_views(settings: &SceneSettings, seed: u64) -> Result<Vec<View>> {
    let s = settings;
    Ok(raycast_precompute::rig::orbit_views(
        s.views,
        s.lights_per_view,
        (s.width, s.height),
        s.camera_distance,
        s.fov_y_deg,
        seed,
    )?)
}
