//! FLIP's spatial filters: the contrast-sensitivity (CSF) Gaussians and the edge and point
//! detectors, all applied as exact separable passes with replicate borders.
//!
//! Every 2D kernel of the reference (NVlabs/flip `generate_spatial_filter`, `feature_detection`)
//! is separable: a CSF kernel is a normalised sum of two isotropic Gaussians, each the outer product
//! of two 1D Gaussians, and the feature kernels are (derivative of g)(x) * g(y) with the sign-wise
//! normalisation depending on x only. Replicate padding is separable too, so the separable passes
//! give the 2D convolution's result up to rounding.

/// A separable 2D kernel: sum over terms of `weight * row(x) * col(y)`, each 1D part with the
/// same radius.
#[derive(Clone, Debug)]
pub struct Separable {
    /// Radius in pixels.
    pub radius: usize,
    /// (weight, horizontal taps, vertical taps).
    pub terms: Vec<(f32, Vec<f32>, Vec<f32>)>,
}

/// CSF constants (a1, b1, a2, b2) for the achromatic, red-green and blue-yellow channels.
pub const CSF: [(f64, f64, f64, f64); 3] =
    [(1.0, 0.0047, 0.0, 1e-5), (1.0, 0.0053, 0.0, 1e-5), (34.1, 0.04, 13.5, 0.025)];

/// Radius of the CSF filters: ceil(3 sqrt(max b / (2 pi^2)) ppd) (10 at the default PPD).
pub fn csf_radius(ppd: f64) -> usize {
    let max_b = CSF.iter().flat_map(|c| [c.1, c.3]).fold(0.0, f64::max);
    (3.0 * (max_b / (2.0 * std::f64::consts::PI.powi(2))).sqrt() * ppd).ceil() as usize
}

/// The CSF kernel of channel `ch` (0 = A, 1 = RG, 2 = BY):
/// g(r^2) = a1 sqrt(pi/b1) exp(-pi^2 r^2 / b1) + a2 sqrt(pi/b2) exp(-pi^2 r^2 / b2), r in degrees,
/// normalised to sum 1 over the (2 radius + 1)^2 grid.
pub fn csf_kernel(ppd: f64, ch: usize) -> Separable {
    use std::f64::consts::PI;
    let r = csf_radius(ppd) as i64;
    let (a1, b1, a2, b2) = CSF[ch];
    let gauss = |b: f64| -> Vec<f64> {
        (-r..=r).map(|i| (-PI * PI * (i as f64 / ppd).powi(2) / b).exp()).collect()
    };
    let (g1, g2) = (gauss(b1), gauss(b2));
    let (s1, s2): (f64, f64) = (g1.iter().sum(), g2.iter().sum());
    let (w1, w2) = (a1 * (PI / b1).sqrt(), a2 * (PI / b2).sqrt());
    let total = w1 * s1 * s1 + w2 * s2 * s2;
    let to32 = |g: &[f64]| g.iter().map(|&v| v as f32).collect::<Vec<_>>();
    let mut terms = vec![((w1 / total) as f32, to32(&g1), to32(&g1))];
    if a2 != 0.0 {
        terms.push(((w2 / total) as f32, to32(&g2), to32(&g2)));
    }
    Separable { radius: r as usize, terms }
}

/// Which feature detector.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Feature {
    /// First derivative of the Gaussian (-x g).
    Edge,
    /// Second derivative ((x^2 / sd^2 - 1) g).
    Point,
}

/// The feature kernel along x (transpose it for y): sd = 0.5 * 0.082 * ppd, radius ceil(3 sd);
/// positive weights sum to +1 and negative weights to -1 over the 2D grid.
pub fn feature_kernel(ppd: f64, feature: Feature) -> Separable {
    let sd = 0.5 * 0.082 * ppd;
    let r = (3.0 * sd).ceil() as i64;
    let g: Vec<f64> = (-r..=r).map(|i| (-((i * i) as f64) / (2.0 * sd * sd)).exp()).collect();
    let d: Vec<f64> = (-r..=r)
        .zip(&g)
        .map(|(i, gi)| match feature {
            Feature::Edge => -(i as f64) * gi,
            Feature::Point => ((i * i) as f64 / (sd * sd) - 1.0) * gi,
        })
        .collect();
    let pos: f64 = d.iter().filter(|&&v| v > 0.0).sum();
    let neg: f64 = -d.iter().filter(|&&v| v < 0.0).sum::<f64>();
    let gs: f64 = g.iter().sum();
    let row: Vec<f32> = d.iter().map(|&v| if v < 0.0 { v / neg } else { v / pos } as f32).collect();
    let col: Vec<f32> = g.iter().map(|&v| (v / gs) as f32).collect();
    Separable { radius: r as usize, terms: vec![(1.0, row, col)] }
}

impl Separable {
    /// The same kernel with rows and columns swapped.
    pub fn transposed(&self) -> Separable {
        Separable {
            radius: self.radius,
            terms: self.terms.iter().map(|(w, r, c)| (*w, c.clone(), r.clone())).collect(),
        }
    }

    /// Correlates a planar row-major image with the kernel, replicate borders.
    ///
    /// Both passes run a whole row at a time (tap by tap, so the inner loop vectorises over
    /// pixels) on a border-extended line; every output sums its taps in the same order as the
    /// direct per-pixel loop, so the result is bit for bit the direct correlation. Where the CPU
    /// has AVX2 the same loops run on its wider vectors ([`stdx::simd::with_avx2`]: the same
    /// operations, so the same bits).
    pub fn apply(&self, src: &[f32], w: usize, h: usize) -> Vec<f32> {
        stdx::simd::with_avx2(|| self.apply_rows(src, w, h))
    }

    #[inline(always)]
    fn apply_rows(&self, src: &[f32], w: usize, h: usize) -> Vec<f32> {
        let r = self.radius;
        let mut out = vec![0.0f32; src.len()];
        if w == 0 || h == 0 {
            return out;
        }
        let mut tmp = vec![0.0f32; src.len()];
        let mut padded = vec![0.0f32; w + 2 * r];
        let mut acc = vec![0.0f32; w];
        for (weight, row, col) in &self.terms {
            for (line, dst) in src.chunks_exact(w).zip(tmp.chunks_exact_mut(w)) {
                for (i, p) in padded.iter_mut().enumerate() {
                    *p = line[i.saturating_sub(r).min(w - 1)];
                }
                dst.fill(0.0);
                for (j, k) in row.iter().enumerate() {
                    for (t, v) in dst.iter_mut().zip(&padded[j..j + w]) {
                        *t += k * v;
                    }
                }
            }
            for (y, dst) in out.chunks_exact_mut(w).enumerate() {
                acc.fill(0.0);
                for (j, k) in col.iter().enumerate() {
                    let yi = (y + j).saturating_sub(r).min(h - 1);
                    for (a, v) in acc.iter_mut().zip(&tmp[yi * w..(yi + 1) * w]) {
                        *a += k * v;
                    }
                }
                for (o, a) in dst.iter_mut().zip(&acc) {
                    *o += weight * a;
                }
            }
        }
        out
    }
}

#[cfg(test)]
#[allow(clippy::needless_range_loop)]
mod tests {
    use super::*;

    const PPD: f64 = 67.020_643_391_292_24;

    #[test]
    fn radii_match_spec() {
        assert_eq!(csf_radius(PPD), 10);
        assert_eq!(feature_kernel(PPD, Feature::Edge).radius, 9);
    }

    /// The separable kernel equals the reference's 2D construction (direct, f64).
    #[test]
    fn separable_equals_2d_construction() {
        use std::f64::consts::PI;
        for ch in 0..3 {
            let k = csf_kernel(PPD, ch);
            let r = k.radius as i64;
            let (a1, b1, a2, b2) = CSF[ch];
            let g2 = |x: i64, y: i64| {
                let z = ((x * x + y * y) as f64) / (PPD * PPD);
                a1 * (PI / b1).sqrt() * (-PI * PI * z / b1).exp()
                    + a2 * (PI / b2).sqrt() * (-PI * PI * z / b2).exp()
            };
            let total: f64 =
                (-r..=r).flat_map(|y| (-r..=r).map(move |x| (x, y))).map(|(x, y)| g2(x, y)).sum();
            for (x, y) in [(0, 0), (3, -2), (10, 10), (-7, 1)] {
                let sep: f64 = k
                    .terms
                    .iter()
                    .map(|(w, rw, cl)| {
                        *w as f64 * rw[(x + r) as usize] as f64 * cl[(y + r) as usize] as f64
                    })
                    .sum();
                let want = g2(x, y) / total;
                assert!((sep - want).abs() <= 1e-6 * want.max(1e-6), "ch {ch} ({x},{y})");
            }
        }
        let e = feature_kernel(PPD, Feature::Point);
        let sd = 0.5 * 0.082 * PPD;
        let r = e.radius as i64;
        let raw = |x: i64, y: i64| {
            ((x * x) as f64 / (sd * sd) - 1.0) * (-((x * x + y * y) as f64) / (2.0 * sd * sd)).exp()
        };
        let grid: Vec<f64> = (-r..=r).flat_map(|y| (-r..=r).map(move |x| raw(x, y))).collect();
        let pos: f64 = grid.iter().filter(|v| **v > 0.0).sum();
        let neg: f64 = -grid.iter().filter(|v| **v < 0.0).sum::<f64>();
        for (x, y) in [(0, 0), (5, 2), (-9, 9)] {
            let v = raw(x, y);
            let want = if v < 0.0 { v / neg } else { v / pos };
            let (_, rw, cl) = &e.terms[0];
            let got = rw[(x + r) as usize] as f64 * cl[(y + r) as usize] as f64;
            assert!((got - want).abs() < 1e-7, "({x},{y}) {got} {want}");
        }
    }

    /// The row-at-a-time correlation equals the direct per-pixel loop bit for bit, on
    /// images smaller and larger than the kernel.
    #[test]
    fn apply_equals_direct_correlation() {
        let direct = |k: &Separable, src: &[f32], w: usize, h: usize| {
            let r = k.radius as i64;
            let mut out = vec![0.0f32; src.len()];
            let mut tmp = vec![0.0f32; src.len()];
            for (weight, row, col) in &k.terms {
                for y in 0..h {
                    for x in 0..w {
                        let mut s = 0.0f32;
                        for (j, kj) in row.iter().enumerate() {
                            let xi = (x as i64 + j as i64 - r).clamp(0, w as i64 - 1) as usize;
                            s += kj * src[y * w + xi];
                        }
                        tmp[y * w + x] = s;
                    }
                }
                for y in 0..h {
                    for x in 0..w {
                        let mut s = 0.0f32;
                        for (j, kj) in col.iter().enumerate() {
                            let yi = (y as i64 + j as i64 - r).clamp(0, h as i64 - 1) as usize;
                            s += kj * tmp[yi * w + x];
                        }
                        out[y * w + x] += weight * s;
                    }
                }
            }
            out
        };
        for (w, h) in [(1, 1), (3, 17), (40, 25)] {
            let src: Vec<f32> = (0..w * h).map(|i| ((i * 7919) % 101) as f32 / 37.0).collect();
            for k in [csf_kernel(PPD, 0), csf_kernel(PPD, 2), feature_kernel(PPD, Feature::Edge)] {
                for k in [k.transposed(), k] {
                    let got = k.apply(&src, w, h);
                    let want = direct(&k, &src, w, h);
                    assert!(got.iter().zip(&want).all(|(a, b)| a.to_bits() == b.to_bits()));
                }
            }
        }
    }

    #[test]
    fn constant_image_is_preserved_by_csf() {
        let src = vec![0.25f32; 7 * 5];
        let k = csf_kernel(PPD, 2);
        for v in k.apply(&src, 7, 5) {
            assert!((v - 0.25).abs() < 1e-6);
        }
    }
}
