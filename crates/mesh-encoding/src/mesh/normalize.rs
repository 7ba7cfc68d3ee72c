//! Normalisation into the unit sphere: translate the bounding-box centre to the origin and scale
//! uniformly so that the farthest vertex lies at distance 1. The map is returned as a
//! [`Similarity`] so that cameras or lights given in the original units can be moved along.

use glam::Vec3;

use super::TriMesh;

/// A uniform scale about a centre: `x' = scale * (x - center)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Similarity {
    /// The point mapped to the origin.
    pub center: Vec3,
    /// The uniform scale factor (> 0).
    pub scale: f32,
}

impl Similarity {
    /// Maps a point.
    pub fn apply(&self, x: Vec3) -> Vec3 {
        self.scale * (x - self.center)
    }

    /// Maps a point back.
    pub fn invert(&self, y: Vec3) -> Vec3 {
        y / self.scale + self.center
    }
}

impl TriMesh {
    /// Moves and scales the mesh into the unit sphere (see the module documentation) and returns
    /// the map applied. A mesh whose vertices all coincide is only translated (scale 1).
    pub fn normalize_unit_sphere(&mut self) -> Similarity {
        let (lo, hi) = self.bounding_box();
        let center = 0.5 * (lo + hi);
        let radius = self.positions.iter().map(|p| p.distance(center)).fold(0.0f32, f32::max);
        let scale = if radius > 0.0 && radius.is_finite() { 1.0 / radius } else { 1.0 };
        let sim = Similarity { center, scale };
        for p in &mut self.positions {
            *p = sim.apply(*p);
        }
        sim
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn farthest_vertex_lands_on_the_unit_sphere() {
        let mut m = TriMesh::new(
            vec![Vec3::new(10.0, 0.0, 0.0), Vec3::new(14.0, 0.0, 0.0), Vec3::new(10.0, 3.0, 0.0)],
            vec![[0, 1, 2]],
        )
        .unwrap();
        let orig = m.positions.clone();
        let sim = m.normalize_unit_sphere();
        assert_eq!(sim.center, Vec3::new(12.0, 1.5, 0.0));
        let r = m.positions.iter().map(|p| p.length()).fold(0.0f32, f32::max);
        assert!((r - 1.0).abs() < 1e-6);
        for (o, p) in orig.iter().zip(&m.positions) {
            assert!((sim.invert(*p) - *o).length() < 1e-5);
        }
    }
}
