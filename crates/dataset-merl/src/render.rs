//! Rendering one (view, light) image of a scene: L = f(l, v) E cos(theta_l) for lit samples, 0
//! for shadowed and back-facing ones, plus Gaussian noise and saturation (spec section 6).
//!
//! Only lit samples evaluate the BRDF: background pixels are not traced, and shadowed or
//! back-facing samples carry no information about it.
//!
//! The radiance is formed in f32 by [`shade`] (the scene format's rendering equation) from the f32 BRDF value that is stored in the
//! scene, the f32 shading normal and light direction: the same function, on the same values,
//! that training and evaluation use. A model that returns the stored ground-truth BRDF
//! therefore renders the scene's noise-free image bit for bit (its noise ceiling is exact).

use raycast_precompute::{Light, LightState, ViewPrecompute};
use scene::flag;
use scene::manifest::LightInfo;
use scene::shading::{facing, light_at, light_weight, shade};

/// The ground-truth BRDF: local-frame (l, v) to RGB in 1/sr, `None` where invalid.
pub type GroundTruth<'a> = dyn Fn([f64; 3], [f64; 3]) -> Option<[f64; 3]> + Sync + 'a;

/// One rendered (view, light) image, full frame, row-major.
pub struct LightImage {
    /// Observed linear radiance (noise and saturation applied).
    pub observed: Vec<[f32; 3]>,
    /// The noise-free radiance, clipped at the saturation level like the observation.
    pub clean: Vec<[f32; 3]>,
    /// Ground-truth BRDF (1/sr) where lit and valid, else 0.
    pub brdf: Vec<[f32; 3]>,
    /// [`flag`] bits per pixel (0 for background).
    pub flags: Vec<u8>,
}

/// Noise and saturation settings of a render.
#[derive(Clone, Copy, Debug)]
pub struct Sensor {
    /// Gaussian noise standard deviation per channel.
    pub noise_sigma: f32,
    /// Clip level.
    pub saturation: f32,
    /// Seed of this image's noise.
    pub seed: u64,
}

/// Normal deviates (Box-Muller) from the workspace's SplitMix64, deterministic per seed.
struct Normal {
    rng: stdx::rng::SplitMix64,
    spare: Option<f64>,
}

impl Normal {
    fn new(seed: u64) -> Self {
        Self { rng: stdx::rng::SplitMix64::new(seed), spare: None }
    }
    fn sample(&mut self) -> f64 {
        if let Some(s) = self.spare.take() {
            return s;
        }
        let u1 = self.rng.next_f64().max(f64::MIN_POSITIVE);
        let u2 = self.rng.next_f64();
        let r = (-2.0 * u1.ln()).sqrt();
        let (s, c) = (std::f64::consts::TAU * u2).sin_cos();
        self.spare = Some(r * s);
        r * c
    }
}

/// Renders light `light` of a view. `info` is the light as the scene's manifest records it:
/// shading uses its direction and irradiance, or a point light's per-sample direction and
/// falloff ([`light_at`]), exactly as training and evaluation will (the precompute holds a
/// renormalised copy of a direction, which may differ in the last bit; the lit/back-facing
/// decision uses that copy, as it always has).
// Channel loops index several per-channel arrays at once.
#[allow(clippy::needless_range_loop)]
pub fn render_light(
    view: &ViewPrecompute,
    light: usize,
    info: &LightInfo,
    gt: &GroundTruth<'_>,
    sensor: Sensor,
) -> LightImage {
    let n_pix = (view.width * view.height) as usize;
    let mut img = LightImage {
        observed: vec![[0.0; 3]; n_pix],
        clean: vec![[0.0; 3]; n_pix],
        brdf: vec![[0.0; 3]; n_pix],
        flags: vec![0; n_pix],
    };
    let mut noise = Normal::new(sensor.seed);
    for k in 0..view.len() {
        let p = view.pixels[k] as usize;
        let n = view.normals[k];
        // What shading uses (the manifest's light), and the direction the lit decision uses.
        let at = light_at(info, view.positions[k].to_array());
        let l_world = match view.lights[light] {
            Light::Directional(d) => Some(d.to_array()),
            Light::Point(_) => at.map(|(l, _)| l),
        };
        let frame = angles::Frame::from_normal([n.x as f64, n.y as f64, n.z as f64]);
        let to_local = |w: [f32; 3]| frame.to_local(w.map(f64::from));
        let v_world = view.view_dirs[k].to_array();
        let above =
            l_world.is_some_and(|l| facing(n.to_array(), l) && facing(n.to_array(), v_world));
        let mut radiance = [0.0_f32; 3];
        let mut flags = match (view.visibility.get(k, light), l_world, at) {
            (LightState::Lit, Some(l_world), Some((direction, irradiance))) if above => {
                match gt(to_local(l_world), to_local(v_world)) {
                    Some(f) => {
                        let f = f.map(|x| x as f32);
                        img.brdf[p] = f;
                        if let Some(w) = light_weight(irradiance, n.to_array(), direction) {
                            radiance = shade(f, w);
                        }
                        flag::LIT | flag::GT_VALID
                    }
                    None => flag::LIT, // invalid table entry: renders black
                }
            }
            (LightState::Shadowed, ..) => flag::SHADOWED,
            _ => flag::BACK_FACING,
        };
        let mut saturated = false;
        for c in 0..3 {
            let x = radiance[c] as f64 + sensor.noise_sigma as f64 * noise.sample();
            let x = x as f32;
            if x >= sensor.saturation {
                saturated = true;
            }
            img.observed[p][c] = x.min(sensor.saturation);
            img.clean[p][c] = radiance[c].min(sensor.saturation);
        }
        if saturated {
            flags |= flag::SATURATED;
        }
        img.flags[p] = flags;
    }
    img
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_deviates_have_unit_variance() {
        let mut n = Normal::new(42);
        let xs: Vec<f64> = (0..200_000).map(|_| n.sample()).collect();
        let mean = xs.iter().sum::<f64>() / xs.len() as f64;
        let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / xs.len() as f64;
        assert!(mean.abs() < 0.01 && (var - 1.0).abs() < 0.01, "{mean} {var}");
    }
}
