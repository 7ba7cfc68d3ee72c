//! Adversarial inputs for the numerics stress tests: direction pairs (shading frame, n = +z) and
//! feature rows built to break a BRDF's arithmetic. Row `i` of a stream is a function of
//! (seed, i) alone, so a failing row can be regenerated from the index a test prints.
//!
//! The pair kinds, cycled through row by row:
//! - grazing: l, v or both at 90 degrees minus 10^-k, k from 1 to 7 (down to 1e-7 rad);
//! - l = v, at any elevation, grazing included;
//! - mirrored (v the reflection of l about n: the specular peak) and l = -v (one below the
//!   horizon);
//! - n.l = 0 or n.v = 0 exactly (z = 0), and both;
//! - denormals: components of 1e-40 and 1e-45 (subnormal f32) beside 1, and pure poles (l = v = n);
//! - below the horizon (z < 0) for either;
//! - uniform on the upper hemisphere.

/// SplitMix64 of (seed, i): the generator behind every row.
fn mix(seed: u64, i: u64, salt: u64) -> u64 {
    let mut z =
        seed ^ i.wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ salt.wrapping_mul(0xd1b5_4a32_d192_ed03);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// A uniform number in [0, 1) from (seed, i, salt).
fn unit(seed: u64, i: u64, salt: u64) -> f64 {
    (mix(seed, i, salt) >> 11) as f64 / (1u64 << 53) as f64
}

/// The direction at polar angle `theta` and azimuth `phi`, normalised in f64.
fn polar(theta: f64, phi: f64) -> [f32; 3] {
    let (s, c) = theta.sin_cos();
    [(s * phi.cos()) as f32, (s * phi.sin()) as f32, c as f32]
}

/// The number of pair kinds ([`direction_pair`] cycles through them).
pub const PAIR_KINDS: u64 = 12;

/// Pair `i` of the stream `seed`: (l, v), unit length (up to f32 rounding) except the denormal
/// kinds, which are as written.
pub fn direction_pair(seed: u64, i: u64) -> ([f32; 3], [f32; 3]) {
    let u = |salt| unit(seed, i, salt);
    let phi = |salt| u(salt) * std::f64::consts::TAU;
    let half_pi = std::f64::consts::FRAC_PI_2;
    let grazing = |salt| half_pi - 10f64.powi(-(1 + (mix(seed, i, salt) % 7) as i32));
    let any = |salt| u(salt).acos(); // uniform in cos theta over the upper hemisphere
    match i % PAIR_KINDS {
        0 => (polar(grazing(1), phi(2)), polar(any(3), phi(4))),
        1 => (polar(any(1), phi(2)), polar(grazing(3), phi(4))),
        2 => (polar(grazing(1), phi(2)), polar(grazing(3), phi(4))),
        3 => {
            let d = if u(5) < 0.5 { polar(grazing(1), phi(2)) } else { polar(any(1), phi(2)) };
            (d, d)
        }
        4 => {
            let l = if u(5) < 0.5 { polar(grazing(1), phi(2)) } else { polar(any(1), phi(2)) };
            (l, [-l[0], -l[1], l[2]])
        }
        5 => {
            let l = polar(any(1), phi(2));
            (l, [-l[0], -l[1], -l[2]])
        }
        6 => (polar(half_pi, phi(2)), polar(any(3), phi(4))),
        7 => (polar(any(1), phi(2)), polar(half_pi, phi(4))),
        8 => (polar(half_pi, phi(2)), polar(half_pi, phi(4))),
        9 => {
            let tiny = [1e-40_f32, 1e-45, 0.0, -1e-40][(mix(seed, i, 6) % 4) as usize];
            let pick = mix(seed, i, 7) % 4;
            let pole = [0.0_f32, 0.0, 1.0];
            let d = [tiny, -tiny, 1.0];
            match pick {
                0 => (pole, pole),
                1 => (d, pole),
                2 => (pole, d),
                _ => ([1.0, tiny, tiny], [tiny, 1.0, tiny]),
            }
        }
        10 => {
            let below = |salt| std::f64::consts::PI - any(salt);
            if u(5) < 0.5 {
                (polar(below(1), phi(2)), polar(any(3), phi(4)))
            } else {
                (polar(any(1), phi(2)), polar(below(3), phi(4)))
            }
        }
        _ => (polar(any(1), phi(2)), polar(any(3), phi(4))),
    }
}

/// Rows `start..start + n` of the pair stream `seed`.
pub fn direction_pairs(seed: u64, start: u64, n: usize) -> (Vec<[f32; 3]>, Vec<[f32; 3]>) {
    (start..start + n as u64).map(|i| direction_pair(seed, i)).unzip()
}

/// Feature rows `start..start + n` (`dim` values each): mostly uniform in [-1, 1]; every
/// fourth row is extreme (values of magnitude 1e2 to 1e4, which drive a parametric model's
/// heads to the ends of their ranges: roughness to 0 or 1, the Phong exponent to its maximum).
pub fn spatial_rows(seed: u64, start: u64, n: usize, dim: usize) -> Vec<f32> {
    let mut out = Vec::with_capacity(n * dim);
    for i in start..start + n as u64 {
        let extreme = i % 4 == 3;
        for j in 0..dim as u64 {
            let x = 2.0 * unit(seed ^ 0x5a5a, i, 100 + j) - 1.0;
            out.push(if extreme {
                (x.signum() * 10f64.powf(2.0 + 2.0 * x.abs())) as f32
            } else {
                x as f32
            });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_kind_appears_and_rows_repeat_by_index() {
        let (l, v) = direction_pairs(7, 0, 1200);
        assert_eq!(direction_pair(7, 345), (l[345], v[345]));
        assert!(l.iter().zip(&v).any(|(a, b)| a == b), "l = v");
        assert!(l.iter().any(|d| d[2] == 0.0) && v.iter().any(|d| d[2] == 0.0), "n.l = 0");
        assert!(l.iter().any(|d| d[0] != 0.0 && d[0].abs() < f32::MIN_POSITIVE), "denormal");
        assert!(l.iter().chain(&v).any(|d| d[2] < 0.0), "below the horizon");
        let min_grazing = l.iter().filter(|d| d[2] > 0.0).map(|d| d[2]).fold(1.0_f32, f32::min);
        assert!(min_grazing < 1e-6, "grazing to 1e-7 rad: {min_grazing}");
        let s = spatial_rows(7, 0, 8, 3);
        assert!(s[9..12].iter().all(|x| x.abs() >= 100.0) && s[..9].iter().all(|x| x.abs() <= 1.0));
    }
}
