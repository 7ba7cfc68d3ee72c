//! A light of a view: directional (at infinity) or a point (with inverse-square falloff, which
//! the scene's shading applies; ray casting needs only where shadow rays go and end).

use glam::Vec3;

/// A light in world space.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Light {
    /// At infinity: the direction from the surface towards the light (normalised on use).
    Directional(Vec3),
    /// At a point: its world position. Shadow rays end there.
    Point(Vec3),
}

impl From<Vec3> for Light {
    /// A directional light towards `direction`.
    fn from(direction: Vec3) -> Self {
        Light::Directional(direction)
    }
}

impl Light {
    /// The unit direction from `x` towards the light and the distance to it (infinite for a
    /// directional light); `None` for a point light at `x` itself.
    pub fn toward(self, x: Vec3) -> Option<(Vec3, f32)> {
        match self {
            Light::Directional(d) => Some((d, f32::INFINITY)),
            Light::Point(p) => {
                let d = p - x;
                let len = d.length();
                (len > 0.0 && len.is_finite()).then(|| (d / len, len))
            }
        }
    }

    /// The direction of a directional light, `None` for a point light.
    pub fn direction(self) -> Option<Vec3> {
        match self {
            Light::Directional(d) => Some(d),
            Light::Point(_) => None,
        }
    }

    /// The light with its direction normalised; `None` when a direction is zero or a vector is
    /// not finite.
    pub(crate) fn validated(self) -> Option<Light> {
        match self {
            Light::Directional(d) => d.try_normalize().map(Light::Directional),
            Light::Point(p) => p.is_finite().then_some(Light::Point(p)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn point_lights_give_direction_and_distance() {
        let (d, r) = Light::Point(Vec3::new(0.0, 3.0, 4.0)).toward(Vec3::ZERO).unwrap();
        assert!((d - Vec3::new(0.0, 0.6, 0.8)).length() < 1e-6 && (r - 5.0).abs() < 1e-6);
        assert_eq!(Light::Point(Vec3::ONE).toward(Vec3::ONE), None);
        assert_eq!(Light::from(Vec3::Z).toward(Vec3::X), Some((Vec3::Z, f32::INFINITY)));
        assert_eq!(Light::Directional(Vec3::ZERO).validated(), None);
        assert_eq!(Light::Point(Vec3::NAN).validated(), None);
    }
}
