//! Per (pixel, light) visibility as two bitsets: `front` (n.l > 0, the light is above the surface
//! at the pixel, so a shadow ray was traced) and `lit` (that shadow ray escaped). Each pixel owns
//! `ceil(lights / 64)` whole 64-bit words in each set, so pixels can be filled in parallel;
//! 512 x 512 pixels x 42 lights take 4 MiB per view.

/// The state of one (pixel, light) pair.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum LightState {
    /// The light is above the surface and the shadow ray escaped.
    Lit,
    /// The light is above the surface but the shadow ray hit the mesh.
    Shadowed,
    /// The light is at or below the surface (n.l <= 0); no ray was traced.
    BackFacing,
}

/// Visibility bits of one view, see the module documentation.
#[derive(Debug, Clone, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub struct Visibility {
    pub(crate) pixels: usize,
    pub(crate) lights: usize,
    pub(crate) lit: Vec<u64>,
    pub(crate) front: Vec<u64>,
}

impl Visibility {
    /// All pairs back-facing, ready to be filled.
    pub(crate) fn new(pixels: usize, lights: usize) -> Self {
        let words = pixels * Self::words_for(lights);
        Visibility { pixels, lights, lit: vec![0; words], front: vec![0; words] }
    }

    /// Words per pixel for `lights` lights.
    pub(crate) fn words_for(lights: usize) -> usize {
        lights.div_ceil(64)
    }

    /// Number of pixels.
    pub fn pixel_count(&self) -> usize {
        self.pixels
    }

    /// Number of lights.
    pub fn light_count(&self) -> usize {
        self.lights
    }

    /// State of (foreground pixel `p`, light `l`), `p` indexing the view's foreground list.
    ///
    /// # Panics
    /// If `p` or `l` is out of range.
    pub fn get(&self, p: usize, l: usize) -> LightState {
        assert!(p < self.pixels && l < self.lights, "({p}, {l}) out of range");
        let w = p * Self::words_for(self.lights) + l / 64;
        let bit = 1u64 << (l % 64);
        match (self.front[w] & bit != 0, self.lit[w] & bit != 0) {
            (false, _) => LightState::BackFacing,
            (true, true) => LightState::Lit,
            (true, false) => LightState::Shadowed,
        }
    }

    /// Whether (p, l) is lit: the shadowing factor 1_s of the rendering equation.
    pub fn is_lit(&self, p: usize, l: usize) -> bool {
        self.get(p, l) == LightState::Lit
    }

    /// Counts of (lit, shadowed, back-facing) pairs.
    pub fn counts(&self) -> (usize, usize, usize) {
        let lit: usize = self.lit.iter().map(|w| w.count_ones() as usize).sum();
        let front: usize = self.front.iter().map(|w| w.count_ones() as usize).sum();
        (lit, front - lit, self.pixels * self.lights - front)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bits_round_trip_across_word_boundaries() {
        let mut v = Visibility::new(3, 70);
        let wpp = Visibility::words_for(70);
        assert_eq!(wpp, 2);
        // pixel 1, light 65: lit; pixel 2, light 3: shadowed.
        v.front[wpp + 1] |= 1 << 1;
        v.lit[wpp + 1] |= 1 << 1;
        v.front[2 * wpp] |= 1 << 3;
        assert_eq!(v.get(1, 65), LightState::Lit);
        assert_eq!(v.get(2, 3), LightState::Shadowed);
        assert_eq!(v.get(0, 0), LightState::BackFacing);
        assert_eq!(v.counts(), (1, 1, 3 * 70 - 2));
    }
}
