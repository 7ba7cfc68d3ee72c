//! The rendering equation of a scene under one light, L = f E cos(theta_l) (spec section 6), in
//! f32: the same function, on the same values, forms the generated radiance, the training
//! targets and the evaluation renders, so a model that returns the stored ground-truth BRDF
//! renders a scene's noise-free image bit for bit (its noise ceiling is exact). A point light's
//! direction and irradiance (inverse-square falloff) at a surface point come from [`light_at`],
//! the one place that computes them.

use crate::manifest::LightInfo;

/// The unit direction l towards `light` and the irradiance E it delivers at the surface point
/// `x` (world space, f32): a directional light's own direction and irradiance; for a point
/// light at p with radiant intensity I, l = (p - x) / |p - x| and E = I / |p - x|^2. `None` at
/// the light's own position.
pub fn light_at(light: &LightInfo, x: [f32; 3]) -> Option<([f32; 3], [f32; 3])> {
    let Some(p) = light.position else {
        return Some((light.direction, light.intensity));
    };
    let d = [p[0] - x[0], p[1] - x[1], p[2] - x[2]];
    let r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    let r = r2.sqrt();
    if !(r > 0.0 && r.is_finite()) {
        return None;
    }
    let i = light.intensity;
    Some(([d[0] / r, d[1] / r, d[2] / r], [i[0] / r2, i[1] / r2, i[2] / r2]))
}

/// Whether the world direction `d` lies above the surface with unit shading normal `n`, decided
/// as the generator and the importers decide it: in f64, in the shading frame.
pub fn facing(n: [f32; 3], d: [f32; 3]) -> bool {
    let frame = angles::Frame::from_normal(n.map(f64::from));
    frame.to_local(d.map(f64::from))[2] > 0.0
}

/// E cos(theta_l) per channel for a unit shading normal `n` and light direction `l` (world
/// space, f32), `None` when cos(theta_l) is not positive: the factor a BRDF value is
/// multiplied by to render a directional light (spec 6).
pub fn light_weight(irradiance: [f32; 3], n: [f32; 3], l: [f32; 3]) -> Option<[f32; 3]> {
    let cos = n[0] * l[0] + n[1] * l[1] + n[2] * l[2];
    if cos.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return None;
    }
    Some([irradiance[0] * cos, irradiance[1] * cos, irradiance[2] * cos])
}

/// The radiance L = f E cos(theta_l) of a BRDF value `f` under a light of weight `w`
/// ([`light_weight`]).
pub fn shade(f: [f32; 3], w: [f32; 3]) -> [f32; 3] {
    [f[0] * w[0], f[1] * w[1], f[2] * w[2]]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grazing_and_back_facing_lights_carry_no_weight() {
        let n = [0.0, 0.0, 1.0];
        assert_eq!(light_weight([1.0; 3], n, [1.0, 0.0, 0.0]), None);
        assert_eq!(light_weight([1.0; 3], n, [0.0, 0.0, -1.0]), None);
        assert_eq!(light_weight([1.0; 3], n, [f32::NAN, 0.0, 0.0]), None);
        let w = light_weight([2.0, 1.0, 0.5], n, [0.0, 0.6, 0.8]).unwrap();
        assert_eq!(shade([1.0; 3], w), [1.6, 0.8, 0.4]);
    }

    #[test]
    fn point_lights_fall_off_with_the_square_of_the_distance() {
        let light = LightInfo {
            direction: [0.0, 0.0, 1.0],
            intensity: [8.0, 4.0, 2.0],
            split: crate::Split::Train,
            source_index: None,
            position: Some([0.0, 0.0, 2.0]),
        };
        let (l, e) = light_at(&light, [0.0, 0.0, 0.0]).unwrap();
        assert_eq!((l, e), ([0.0, 0.0, 1.0], [2.0, 1.0, 0.5]));
        let (_, e4) = light_at(&light, [0.0, 0.0, -2.0]).unwrap();
        assert_eq!(e4, [0.5, 0.25, 0.125]);
        assert_eq!(light_at(&light, [0.0, 0.0, 2.0]), None);
        let directional = LightInfo { position: None, ..light };
        assert_eq!(
            light_at(&directional, [5.0, 1.0, 0.0]),
            Some(([0.0, 0.0, 1.0], [8.0, 4.0, 2.0]))
        );
        assert!(
            facing([0.0, 0.0, 1.0], [0.0, 0.6, 0.8]) && !facing([0.0, 0.0, 1.0], [1.0, 0.0, 0.0])
        );
    }
}
