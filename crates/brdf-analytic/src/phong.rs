//! Realistic Phong: the energy-conserving modified Phong model of Lafortune and Willems (1994).

use crate::brdf::{Brdf, BrdfSample, Rgb};
use crate::params::{ParamError, check, check_rgb, clamp_or, clamp_rgb};
use crate::sampling::{
    above_horizon, clamp_uniform, cosine_hemisphere, cosine_pdf, finish, lobe_probabilities, mean3,
    phong_lobe, phong_lobe_pdf, pick_lobe,
};
use angles::{Real, Vec3};

/// Parameters of [`RealisticPhong`].
///
/// | parameter | range | unit | default |
/// | --- | --- | --- | --- |
/// | `kd` | [0, 1]^3 | - | 0.4 |
/// | `ks` | [0, 1]^3, with kd + ks <= 1 per channel | - | 0.4 |
/// | `exponent` | [1, 1e6] | - | 32 |
///
/// The paper's network predicts k = sigmoid(.) and a split zeta = sigmoid(.) with kd = zeta k and
/// ks = (1 - zeta) k ([`RealisticPhongParams::from_split`]), and N = 1 + softplus(.).
///
/// Sampling: a one-sample mixture (balance heuristic) of the cosine-weighted hemisphere
/// (diffuse) and the lobe (N + 1)/(2 pi) cos^N about the mirror direction of v (specular), picked
/// with probabilities from mean(kd) and mean(ks) (each at least 5 %); pdf = the mixture density.
/// A lobe direction below the horizon is no sample (`None`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RealisticPhongParams<T> {
    /// Diffuse coefficient, linear RGB.
    pub kd: Rgb<T>,
    /// Specular coefficient, linear RGB.
    pub ks: Rgb<T>,
    /// Phong exponent N.
    pub exponent: T,
}

impl<T: Real> Default for RealisticPhongParams<T> {
    fn default() -> Self {
        Self { kd: [T::lit(0.4); 3], ks: [T::lit(0.4); 3], exponent: T::lit(32.0) }
    }
}

impl<T: Real> RealisticPhongParams<T> {
    /// Parameters from the network's split form: kd = zeta k, ks = (1 - zeta) k.
    pub fn from_split(k: Rgb<T>, zeta: Rgb<T>, exponent: T) -> Self {
        let kd = [0, 1, 2].map(|c| zeta[c] * k[c]);
        let ks = [0, 1, 2].map(|c| (T::one() - zeta[c]) * k[c]);
        Self { kd, ks, exponent }
    }
}

/// Largest exponent accepted.
const MAX_EXPONENT: f64 = 1e6;

/// The Realistic Phong BRDF (Lafortune and Willems 1994, "Using the modified Phong reflectance
/// model for physically based rendering"; [P supp. "Realistic Phong Model"]):
///
/// f(l, v) = kd / pi + ks (N + 2) / (2 pi) max(0, r.v)^N, with r = 2 (n.l) n - l.
///
/// Energy-conserving whenever kd + ks <= 1 per channel (the lobe's albedo is at most ks, reached
/// at normal incidence), which the constructor enforces. Reciprocal: r.v = 2 (n.l)(n.v) - l.v is
/// symmetric, and the code computes it symmetrically.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RealisticPhong<T> {
    params: RealisticPhongParams<T>,
    diffuse: Rgb<T>,
    lobe: Rgb<T>,
}

impl<T: Real> RealisticPhong<T> {
    /// Builds the model: coefficients are clamped into [0, 1] (NaN becomes 0.4); where
    /// kd + ks > 1 both are scaled by 1 / (kd + ks); the exponent is clamped into [1, 1e6]
    /// (NaN becomes 32).
    pub fn new(params: RealisticPhongParams<T>) -> Self {
        let mut kd = clamp_rgb(params.kd, 0.0, 1.0, 0.4);
        let mut ks = clamp_rgb(params.ks, 0.0, 1.0, 0.4);
        for c in 0..3 {
            let sum = kd[c] + ks[c];
            if sum > T::one() {
                kd[c] = kd[c] / sum;
                ks[c] = (T::one() - kd[c]).min(ks[c] / sum);
            }
        }
        let exponent = clamp_or(params.exponent, 1.0, MAX_EXPONENT, 32.0);
        let norm = (exponent + T::lit(2.0)) / T::TAU();
        Self {
            params: RealisticPhongParams { kd, ks, exponent },
            diffuse: kd.map(|k| k * T::FRAC_1_PI()),
            lobe: ks.map(|k| k * norm),
        }
    }

    /// Builds the model, rejecting coefficients outside [0, 1], kd + ks > 1 or an exponent
    /// outside [1, 1e6].
    pub fn try_new(params: RealisticPhongParams<T>) -> Result<Self, ParamError> {
        const M: &str = "RealisticPhong";
        check_rgb(M, "kd", params.kd, 0.0, 1.0)?;
        check_rgb(M, "ks", params.ks, 0.0, 1.0)?;
        for c in 0..3 {
            check(M, "kd + ks", params.kd[c] + params.ks[c], 0.0, 1.0)?;
        }
        check(M, "exponent", params.exponent, 1.0, MAX_EXPONENT)?;
        Ok(Self::new(params))
    }

    /// The parameters in use (after clamping).
    pub fn params(&self) -> &RealisticPhongParams<T> {
        &self.params
    }

    /// Probabilities of picking the diffuse and the lobe sampler.
    #[inline]
    fn lobe_probabilities(&self) -> [T; 2] {
        lobe_probabilities([mean3(self.params.kd), mean3(self.params.ks)])
    }

    /// The mixture density for v, l above the horizon and the probabilities `p`.
    #[inline]
    fn mixture_pdf(&self, v: Vec3<T>, l: Vec3<T>, p: [T; 2]) -> T {
        // r.v = l.r_v with r_v the mirror direction of v, computed as in `eval`.
        let rv = l[2] * v[2] - (l[0] * v[0] + l[1] * v[1]);
        p[0] * cosine_pdf(l[2]) + p[1] * phong_lobe_pdf(rv, self.params.exponent)
    }
}

impl<T: Real> Brdf<T> for RealisticPhong<T> {
    #[inline(always)]
    fn eval(&self, l: Vec3<T>, v: Vec3<T>) -> Rgb<T> {
        let zero = T::zero();
        if !(l[2] > zero && v[2] > zero) {
            return [zero; 3];
        }
        // r.v with r = (-l_x, -l_y, l_z) in the local frame.
        let rv = l[2] * v[2] - (l[0] * v[0] + l[1] * v[1]);
        let spec = if rv > zero { rv.min(T::one()).powf(self.params.exponent) } else { zero };
        [0, 1, 2].map(|c| self.diffuse[c] + self.lobe[c] * spec)
    }

    fn name(&self) -> &'static str {
        "RP"
    }

    /// Mixture of the cosine hemisphere and the cos^N lobe about the mirror direction of v.
    fn sample(&self, v: Vec3<T>, u: [T; 2]) -> Option<BrdfSample<T>> {
        if !above_horizon(v) {
            return None;
        }
        let p = self.lobe_probabilities();
        let (k, u0) = pick_lobe(p, clamp_uniform(u[0]));
        let u = [u0, clamp_uniform(u[1])];
        let l = if k == 0 {
            cosine_hemisphere(u)
        } else {
            phong_lobe([-v[0], -v[1], v[2]], self.params.exponent, u)
        };
        if !above_horizon(l) {
            return None;
        }
        finish(self, v, l, self.mixture_pdf(v, l, p))
    }

    fn pdf(&self, v: Vec3<T>, l: Vec3<T>) -> T {
        if l[2] > T::zero() && v[2] > T::zero() {
            self.mixture_pdf(v, l, self.lobe_probabilities())
        } else {
            T::zero()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closed_form_value_and_clamping() {
        let p = RealisticPhongParams { kd: [0.2_f64; 3], ks: [0.5; 3], exponent: 10.0 };
        let m = RealisticPhong::try_new(p).unwrap();
        // Mirror configuration: r = v, the lobe peaks.
        let t = 0.5_f64;
        let (l, v) = ([t.sin(), 0.0, t.cos()], [-t.sin(), 0.0, t.cos()]);
        let expect = 0.2 / std::f64::consts::PI + 0.5 * 12.0 / std::f64::consts::TAU;
        assert!((m.eval(l, v)[0] - expect).abs() < 1e-14);
        let bad = RealisticPhongParams { kd: [0.7_f32; 3], ks: [0.6; 3], exponent: 0.5 };
        assert!(RealisticPhong::try_new(bad).is_err());
        let c = RealisticPhong::new(bad);
        assert!(c.params().kd[0] + c.params().ks[0] <= 1.0);
        assert_eq!(c.params().exponent, 1.0);
        let s = RealisticPhongParams::from_split([0.8_f64; 3], [0.25; 3], 5.0);
        assert_eq!((s.kd[0], s.ks[0]), (0.2, 0.6000000000000001));
    }
}
