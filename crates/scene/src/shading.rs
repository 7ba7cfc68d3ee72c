//! The rendering equation of a scene under one directional light, L = f E cos(theta_l) (spec
//! section 6), in f32: the same function, on the same values, forms the generated radiance, the
//! training targets and the evaluation renders, so a model that returns the stored ground-truth
//! BRDF renders a scene's noise-free image bit for bit (its noise ceiling is exact).

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
}
