//! A chi^2 goodness-of-fit test of a BRDF's sampler against its density, after Mitsuba 3's
//! `mitsuba.python.chi2` (Jakob et al.), with two changes: the bins adapt to the distribution,
//! and failed samples form a cell of their own.
//!
//! Procedure for one (model, v):
//! 1. Bins: a tensor grid in spherical coordinates (theta in [0, pi/2] from the normal, phi in
//!    [0, 2 pi)). The edges are quantiles of a pilot set: directions drawn by the sampler itself
//!    with an independent seed, pooled with as many directions uniform in solid angle, so that
//!    narrow lobes get narrow bins and the rest of the hemisphere is still covered. The pilot is
//!    independent of the test draw, so the partition is fixed with respect to it, as the chi^2
//!    test requires.
//! 2. Observed: N calls of `sample(v, u)` with seeded uniforms; each returned l is counted in its
//!    bin, each `None` in the failure cell.
//! 3. Expected: N times the integral of `pdf(v, l)` sin(theta) over each bin, by adaptive
//!    Gauss-Legendre cubature (5 x 5 nodes against the four 5 x 5 quarters, recursing to an
//!    absolute tolerance of 1e-10 of probability mass) on a finer grid (each bin split 4 x 4 at
//!    the pilot's quantiles inside it, so that nodes land in a narrow lobe's tail even where
//!    it spills into a wide bin); the failure cell expects
//!    N (1 - integral over the hemisphere), so a density that integrates to more than the
//!    success rate, or a sampler that fails more often than the density says, is caught too.
//! 4. Cells sorted by expected count; those below 5 pooled in order until the pool exceeds 5
//!    (Mitsuba's `chi2`); statistic sum (O - E)^2 / E over the cells, dof = cells - 1, p-value =
//!    Q(dof / 2, chi^2 / 2), the regularized upper incomplete gamma function. Any sample in a
//!    cell whose expected count is exactly 0 fails the test outright.

use brdf_analytic::quadrature::gauss_legendre;
use brdf_analytic::{Brdf, Real};
use std::f64::consts::{FRAC_PI_2, TAU};
use stdx::rng::SplitMix64;

/// One chi^2 run's settings.
#[derive(Clone, Copy, Debug)]
pub struct Chi2Config {
    /// Test draws N.
    pub samples: usize,
    /// Pilot draws from the sampler (as many uniform directions are added) for the bin edges.
    pub pilot: usize,
    /// Bins in theta and in phi.
    pub theta_bins: usize,
    pub phi_bins: usize,
    /// Seed of the test draw (the pilot uses a derived seed).
    pub seed: u64,
}

impl Default for Chi2Config {
    fn default() -> Self {
        Self { samples: 1_000_000, pilot: 40_000, theta_bins: 16, phi_bins: 32, seed: 0x5EED_C412 }
    }
}

/// The outcome of one chi^2 run.
#[derive(Clone, Debug)]
pub struct Chi2Outcome {
    /// The statistic, its degrees of freedom and the p-value.
    pub statistic: f64,
    pub dof: usize,
    pub p_value: f64,
    /// Integral of the pdf over the upper hemisphere (by the cubature) and the measured
    /// success rate of `sample` (returned `Some`).
    pub pdf_integral: f64,
    pub success_rate: f64,
    /// Samples that fell in cells with expected count exactly 0.
    pub impossible_samples: usize,
    /// Cells before pooling, and how many went into pools.
    pub cells: usize,
    pub pooled: usize,
}

/// Spherical coordinates (theta from +z, phi in [0, 2 pi)) of a direction.
pub fn spherical_coords(l: [f64; 3]) -> (f64, f64) {
    let theta = l[0].hypot(l[1]).atan2(l[2]);
    let mut phi = l[1].atan2(l[0]);
    if phi < 0.0 {
        phi += TAU;
    }
    (theta, phi.min(TAU))
}

/// Runs `sample` `n` times from `seed`: the successful directions' coordinates, and the number
/// of failures.
fn draw<T: Real, B: Brdf<T> + ?Sized>(
    brdf: &B,
    v: [T; 3],
    n: usize,
    seed: u64,
) -> (Vec<(f64, f64)>, usize) {
    let mut rng = SplitMix64::new(seed);
    let mut out = Vec::with_capacity(n);
    let mut failures = 0;
    for _ in 0..n {
        let u = [T::lit(rng.next_f64()), T::lit(rng.next_f64())];
        match brdf.sample(v, u) {
            Some(s) => out.push(spherical_coords(s.l.map(|x| x.to_f64_exact()))),
            None => failures += 1,
        }
    }
    (out, failures)
}

/// `bins` + 1 strictly increasing edges from `lo` to `hi` at the quantiles of `sorted` (values
/// in [lo, hi], sorted), at least 1e-6 apart.
fn quantile_edges(sorted: &[f64], bins: usize, lo: f64, hi: f64) -> Vec<f64> {
    let mut edges = vec![lo];
    for k in 1..bins {
        let q = if sorted.is_empty() {
            lo + (hi - lo) * k as f64 / bins as f64
        } else {
            sorted[(sorted.len() * k / bins).min(sorted.len() - 1)]
        };
        if q > edges[edges.len() - 1] + 1e-6 && q < hi - 1e-6 {
            edges.push(q);
        }
    }
    edges.push(hi);
    edges
}

/// Every interval of `edges` split at `k` quantiles of the values of `sorted` inside it: the
/// finer grid the cubature works on, dense where the pilot's mass is.
fn refine_edges(edges: &[f64], sorted: &[f64], k: usize) -> Vec<Vec<f64>> {
    edges
        .windows(2)
        .map(|w| {
            let (a, b) =
                (sorted.partition_point(|&x| x < w[0]), sorted.partition_point(|&x| x < w[1]));
            quantile_edges(&sorted[a..b], k, w[0], w[1])
        })
        .collect()
}

/// Adaptive Gauss-Legendre cubature of `f(theta, phi)` over rectangles.
struct Cubature<F> {
    f: F,
    rule: Vec<(f64, f64)>,
}

impl<F: Fn(f64, f64) -> f64> Cubature<F> {
    fn fixed(&self, t0: f64, t1: f64, p0: f64, p1: f64) -> f64 {
        let (ct, ht, cp, hp) = (0.5 * (t0 + t1), 0.5 * (t1 - t0), 0.5 * (p0 + p1), 0.5 * (p1 - p0));
        let mut s = 0.0;
        for &(xt, wt) in &self.rule {
            for &(xp, wp) in &self.rule {
                s += wt * wp * (self.f)(ct + ht * xt, cp + hp * xp);
            }
        }
        s * ht * hp
    }

    fn adaptive(&self, r: [f64; 4], whole: f64, tol: f64, depth: u32) -> f64 {
        let [t0, t1, p0, p1] = r;
        let (tm, pm) = (0.5 * (t0 + t1), 0.5 * (p0 + p1));
        let quads = [[t0, tm, p0, pm], [tm, t1, p0, pm], [t0, tm, pm, p1], [tm, t1, pm, p1]];
        let parts = quads.map(|q| self.fixed(q[0], q[1], q[2], q[3]));
        let sum: f64 = parts.iter().sum();
        if depth == 0 || (sum - whole).abs() <= tol {
            return sum;
        }
        (0..4).map(|i| self.adaptive(quads[i], parts[i], 0.5 * tol, depth - 1)).sum()
    }

    fn integrate(&self, t0: f64, t1: f64, p0: f64, p1: f64, tol: f64) -> f64 {
        let whole = self.fixed(t0, t1, p0, p1);
        self.adaptive([t0, t1, p0, p1], whole, tol, 12)
    }
}

/// The chi^2 test of `brdf`'s sampler against its pdf for the view direction `v` (unit, f64;
/// rounded to `T` for the model).
pub fn chi2_test<T: Real, B: Brdf<T> + ?Sized>(
    brdf: &B,
    v: [f64; 3],
    cfg: Chi2Config,
) -> Chi2Outcome {
    let vt = v.map(T::lit);

    // 1. Bin edges from the pilot set plus uniform directions.
    let (pilot, _) = draw(brdf, vt, cfg.pilot, cfg.seed ^ 0x9E37_79B9_7F4A_7C15);
    let mut rng = SplitMix64::new(cfg.seed.wrapping_add(17));
    let uniform = (0..cfg.pilot).map(|_| {
        let z: f64 = rng.next_f64();
        (z.acos(), TAU * rng.next_f64())
    });
    let all: Vec<(f64, f64)> = pilot.iter().copied().chain(uniform).collect();
    let sorted = |f: fn(&(f64, f64)) -> f64| {
        let mut x: Vec<f64> = all.iter().map(f).collect();
        x.sort_by(f64::total_cmp);
        x
    };
    let (thetas, phis) = (sorted(|p| p.0), sorted(|p| p.1));
    let theta_edges = quantile_edges(&thetas, cfg.theta_bins, 0.0, FRAC_PI_2);
    let phi_edges = quantile_edges(&phis, cfg.phi_bins, 0.0, TAU);
    let (nt, np) = (theta_edges.len() - 1, phi_edges.len() - 1);
    // The cubature's grid: each bin split at REFINE x REFINE quantiles of the pilot inside it, so
    // that a lobe's tail beside a wide bin is not left between the nodes.
    const REFINE: usize = 4;
    let theta_sub = refine_edges(&theta_edges, &thetas, REFINE);
    let phi_sub = refine_edges(&phi_edges, &phis, REFINE);

    // 2. Observed counts.
    let (points, failures) = draw(brdf, vt, cfg.samples, cfg.seed);
    let mut observed = vec![0.0_f64; nt * np + 1];
    let bin =
        |edges: &[f64], x: f64| edges.partition_point(|&e| e <= x).clamp(1, edges.len() - 1) - 1;
    for &(t, p) in &points {
        observed[bin(&theta_edges, t) * np + bin(&phi_edges, p)] += 1.0;
    }
    observed[nt * np] = failures as f64;

    // 3. Expected counts.
    let cub = Cubature {
        f: |t: f64, p: f64| {
            let (st, ct) = t.sin_cos();
            let l = [st * p.cos(), st * p.sin(), ct].map(T::lit);
            brdf.pdf(vt, l).to_f64_exact() * st
        },
        rule: gauss_legendre(5),
    };
    let n = cfg.samples as f64;
    let mut expected = vec![0.0_f64; nt * np + 1];
    let mut integral = 0.0;
    for i in 0..nt {
        for j in 0..np {
            let mut m = 0.0;
            for t in theta_sub[i].windows(2) {
                for p in phi_sub[j].windows(2) {
                    m += cub.integrate(t[0], t[1], p[0], p[1], 1e-10);
                }
            }
            integral += m;
            expected[i * np + j] = n * m;
        }
    }
    expected[nt * np] = (n * (1.0 - integral)).max(0.0);

    // 4. Pooling and the statistic, as Mitsuba's `chi2`.
    let impossible_samples =
        (0..expected.len()).filter(|&k| expected[k] == 0.0).map(|k| observed[k] as usize).sum();
    let mut order: Vec<usize> = (0..expected.len()).collect();
    order.sort_by(|&a, &b| expected[a].total_cmp(&expected[b]));
    let (mut pooled_obs, mut pooled_exp, mut chi2, mut terms, mut pooled) =
        (0.0, 0.0, 0.0, 0usize, 0usize);
    for k in order {
        let (o, e) = (observed[k], expected[k]);
        if o == 0.0 && e == 0.0 {
            continue;
        }
        if e < 5.0 {
            pooled_obs += o;
            pooled_exp += e;
            pooled += 1;
            if pooled_exp > 5.0 {
                chi2 += (pooled_obs - pooled_exp) * (pooled_obs - pooled_exp) / pooled_exp;
                terms += 1;
                (pooled_obs, pooled_exp) = (0.0, 0.0);
            }
        } else {
            chi2 += (o - e) * (o - e) / e;
            terms += 1;
        }
    }
    if pooled_exp > 0.0 {
        chi2 += (pooled_obs - pooled_exp) * (pooled_obs - pooled_exp) / pooled_exp;
        terms += 1;
    } else if pooled_obs > 0.0 {
        chi2 = f64::INFINITY;
    }
    let dof = terms.saturating_sub(1).max(1);
    Chi2Outcome {
        statistic: chi2,
        dof,
        p_value: gamma_q(0.5 * dof as f64, 0.5 * chi2),
        pdf_integral: integral,
        success_rate: points.len() as f64 / n,
        impossible_samples,
        cells: expected.len(),
        pooled,
    }
}

/// The Sidak-corrected p-value threshold for `tests` tests at overall significance `alpha`:
/// 1 - (1 - alpha)^(1 / tests).
pub fn sidak_threshold(alpha: f64, tests: usize) -> f64 {
    1.0 - (1.0 - alpha).powf(1.0 / tests as f64)
}

/// ln Gamma(x) for x > 0 (Lanczos, g = 7, 9 terms; relative error ~1e-15).
pub fn ln_gamma(x: f64) -> f64 {
    const G: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        // Reflection: Gamma(x) Gamma(1 - x) = pi / sin(pi x).
        return (std::f64::consts::PI / (std::f64::consts::PI * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut a = G[0];
    let t = x + 7.5;
    for (i, g) in G.iter().enumerate().skip(1) {
        a += g / (x + i as f64);
    }
    0.5 * (TAU).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// The regularized upper incomplete gamma function Q(a, x) = Gamma(a, x) / Gamma(a), a > 0,
/// x >= 0: by its series for x < a + 1 (Q = 1 - P), else by its continued fraction (modified
/// Lentz), as in Numerical Recipes' `gammq`.
pub fn gamma_q(a: f64, x: f64) -> f64 {
    if x.is_nan() || a <= 0.0 {
        return f64::NAN;
    }
    if x <= 0.0 {
        return 1.0;
    }
    if x.is_infinite() {
        return 0.0;
    }
    let log_prefactor = -x + a * x.ln() - ln_gamma(a);
    if x < a + 1.0 {
        // P(a, x) = e^-x x^a / Gamma(a + 1) sum_n x^n / ((a + 1)...(a + n)).
        let (mut term, mut sum, mut ap) = (1.0 / a, 1.0 / a, a);
        for _ in 0..100_000 {
            ap += 1.0;
            term *= x / ap;
            sum += term;
            if term.abs() < sum.abs() * 1e-16 {
                break;
            }
        }
        1.0 - sum * log_prefactor.exp()
    } else {
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..100_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < tiny {
                d = tiny;
            }
            c = b + an / c;
            if c.abs() < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            let delta = d * c;
            h *= delta;
            if (delta - 1.0).abs() < 1e-16 {
                break;
            }
        }
        log_prefactor.exp() * h
    }
}
