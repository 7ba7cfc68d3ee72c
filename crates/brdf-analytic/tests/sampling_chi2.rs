//! chi^2 goodness-of-fit of every model's sampler against its pdf (procedure in
//! `common/chi2.rs`, after Mitsuba 3): several roughnesses (or exponents, or FMBRDF widths) and
//! view angles per model, grazing included, in f64 and, for one configuration each, in f32.
//! Significance 0.01 over the whole table with the Sidak correction; fixed seeds. Negative
//! controls at the end check that the test rejects slightly wrong samplers.
//!
//! `cargo test -p brdf-analytic --test sampling_chi2 -- --nocapture` prints the table.

mod common;

use brdf_analytic::*;
use common::chi2::{Chi2Config, Chi2Outcome, chi2_test, sidak_threshold};
use common::{dir_deg, disney_all_lobes};

/// Overall significance of the table (Mitsuba's default).
const SIGNIFICANCE: f64 = 0.01;

#[derive(Clone, Copy, Debug)]
enum Model {
    Lambert,
    /// Realistic Phong with this exponent (kd 0.3, ks 0.6).
    Phong(f64),
    /// Torrance-Sparrow dielectric (diffuse (0.5, 0.4, 0.3), F0 0.04) with this roughness.
    TsPlastic(f64),
    /// Torrance-Sparrow metal (diffuse 0, F0 (0.9, 0.7, 0.5)) with this roughness.
    TsMetal(f64),
    /// Disney with every lobe (`disney_all_lobes`) at this roughness and clear-coat gloss.
    DisneyAll(f64, f64),
    /// Disney at its defaults (no clear coat) with this roughness.
    DisneyDefault(f64),
    /// Disney metal (metallic 1, no clear coat) with this roughness.
    DisneyMetal(f64),
    /// FMBRDF at (alpha, beta, k_s), other parameters default.
    Fmbrdf(f64, f64, f64),
    /// A model that overrides neither `sample` nor `pdf` (the trait's cosine defaults), with
    /// the Torrance-Sparrow dielectric's `eval` at this roughness.
    TraitDefault(f64),
}

/// Torrance-Sparrow's `eval` only: samples through the trait's default methods.
struct EvalOnly<T>(TorranceSparrow<T>);

impl<T: Real> Brdf<T> for EvalOnly<T> {
    fn eval(&self, l: [T; 3], v: [T; 3]) -> Rgb<T> {
        self.0.eval(l, v)
    }
    fn name(&self) -> &'static str {
        "eval-only"
    }
}

#[derive(Clone, Copy, Debug)]
struct Case {
    model: Model,
    view_deg: f64,
    f32: bool,
}

const fn c(model: Model, view_deg: f64) -> Case {
    Case { model, view_deg, f32: false }
}
const fn c32(model: Model, view_deg: f64) -> Case {
    Case { model, view_deg, f32: true }
}

/// Realistic Phong exponents matching GGX roughness 1, 0.3 and 0.05 by N = 2 / alpha^2 - 2,
/// alpha = roughness^2 (Walter et al. 2007's Phong-Beckmann correspondence; N >= 1).
const PHONG_R1: f64 = 1.0;
const PHONG_R03: f64 = 245.0;
const PHONG_R005: f64 = 3.2e5;

/// Every configuration of the table: the Sidak correction counts all of them.
const CASES: &[Case] = &[
    c(Model::Lambert, 0.0),
    c(Model::Lambert, 45.0),
    c(Model::Lambert, 75.0),
    c(Model::Lambert, 89.0),
    c32(Model::Lambert, 45.0),
    c(Model::Phong(PHONG_R1), 0.0),
    c(Model::Phong(PHONG_R1), 88.0),
    c(Model::Phong(PHONG_R03), 45.0),
    c(Model::Phong(PHONG_R03), 88.0),
    c(Model::Phong(PHONG_R005), 0.0),
    c(Model::Phong(PHONG_R005), 45.0),
    c32(Model::Phong(PHONG_R03), 45.0),
    c(Model::TsPlastic(0.05), 0.0),
    c(Model::TsPlastic(0.05), 45.0),
    c(Model::TsPlastic(0.3), 45.0),
    c(Model::TsPlastic(0.3), 88.0),
    c(Model::TsPlastic(1.0), 0.0),
    c(Model::TsMetal(0.0), 45.0),
    c(Model::TsMetal(0.3), 85.0),
    c(Model::TsMetal(1.0), 88.0),
    c32(Model::TsMetal(0.3), 45.0),
    c(Model::DisneyAll(0.05, 0.7), 45.0),
    c(Model::DisneyAll(0.3, 0.7), 0.0),
    c(Model::DisneyAll(0.3, 1.0), 60.0),
    c(Model::DisneyAll(1.0, 0.0), 88.0),
    c(Model::DisneyDefault(0.5), 60.0),
    c(Model::DisneyMetal(0.05), 85.0),
    c(Model::DisneyMetal(1.0), 0.0),
    c32(Model::DisneyAll(0.3, 0.7), 45.0),
    c(Model::Fmbrdf(0.05, 2.0, 1.0), 45.0),
    c(Model::Fmbrdf(0.3, 2.0, 1.0), 0.0),
    c(Model::Fmbrdf(0.3, 2.0, 20.0), 88.0),
    c(Model::Fmbrdf(1.0, 2.0, 1.0), 45.0),
    c(Model::Fmbrdf(0.3, 0.5, 20.0), 60.0),
    c32(Model::Fmbrdf(0.3, 2.0, 20.0), 45.0),
    c(Model::TraitDefault(0.3), 60.0),
];

fn build<T: Real>(m: Model) -> Box<dyn Brdf<T>> {
    let l = T::lit;
    match m {
        Model::Lambert => Box::new(Lambert::new(LambertParams { albedo: [l(0.5); 3] })),
        Model::Phong(n) => Box::new(RealisticPhong::new(RealisticPhongParams {
            kd: [l(0.3); 3],
            ks: [l(0.6); 3],
            exponent: l(n),
        })),
        Model::TsPlastic(r) => Box::new(TorranceSparrow::new(TorranceSparrowParams {
            roughness: l(r),
            diffuse: [l(0.5), l(0.4), l(0.3)],
            f0: [l(0.04); 3],
        })),
        Model::TraitDefault(r) => Box::new(EvalOnly(TorranceSparrow::new(TorranceSparrowParams {
            roughness: l(r),
            diffuse: [l(0.5), l(0.4), l(0.3)],
            f0: [l(0.04); 3],
        }))),
        Model::TsMetal(r) => Box::new(TorranceSparrow::new(TorranceSparrowParams {
            roughness: l(r),
            diffuse: [T::zero(); 3],
            f0: [l(0.9), l(0.7), l(0.5)],
        })),
        Model::DisneyAll(r, gloss) => Box::new(Disney::new(DisneyParams {
            roughness: l(r),
            clearcoat_gloss: l(gloss),
            ..disney_all_lobes()
        })),
        Model::DisneyDefault(r) => {
            Box::new(Disney::new(DisneyParams { roughness: l(r), ..Default::default() }))
        }
        Model::DisneyMetal(r) => Box::new(Disney::new(DisneyParams {
            base_color: [l(0.9), l(0.6), l(0.3)],
            metallic: T::one(),
            roughness: l(r),
            ..Default::default()
        })),
        Model::Fmbrdf(alpha, beta, k_s) => Box::new(Fmbrdf::new(FmbrdfParams {
            alpha: l(alpha),
            beta: l(beta),
            k_s: l(k_s),
            ..Default::default()
        })),
    }
}

fn run(case: &Case, index: usize) -> Chi2Outcome {
    let mut cfg = Chi2Config { seed: 0xC412_0000 + index as u64, ..Chi2Config::default() };
    if matches!(case.model, Model::Fmbrdf(..)) {
        // Each FMBRDF sample evaluates its two networks for the weight: fewer draws.
        cfg.samples = 250_000;
        cfg.pilot = 20_000;
    }
    let v = dir_deg(case.view_deg);
    if case.f32 {
        chi2_test(&build::<f32>(case.model), v, cfg)
    } else {
        chi2_test(&build::<f64>(case.model), v, cfg)
    }
}

/// Runs the cases of one model family, prints their rows and checks them.
fn check(family: impl Fn(&Model) -> bool) {
    let threshold = sidak_threshold(SIGNIFICANCE, CASES.len());
    let mut failures = Vec::new();
    for (i, case) in CASES.iter().enumerate().filter(|(_, c)| family(&c.model)) {
        let o = run(case, i);
        let n = if matches!(case.model, Model::Fmbrdf(..)) { 250_000.0 } else { 1e6 };
        let row = format!(
            "| {:?} | {} | {} | {:.1} | {} | {:.3e} | {:.6} | {:.6} |",
            case.model,
            case.view_deg,
            if case.f32 { "f32" } else { "f64" },
            o.statistic,
            o.dof,
            o.p_value,
            o.pdf_integral,
            o.success_rate
        );
        eprintln!("{row}");
        // The failure cell is part of the statistic; these say the same more directly.
        let se = (o.pdf_integral.clamp(0.0, 1.0) * (1.0 - o.pdf_integral.min(1.0)) / n).sqrt();
        let integral_ok = o.pdf_integral <= 1.0 + 1e-6
            && (o.pdf_integral - o.success_rate).abs() <= 5.0 * se + 1e-5;
        if !(o.p_value >= threshold && o.impossible_samples == 0 && integral_ok) {
            failures.push(format!("{row} {o:?}"));
        }
    }
    assert!(failures.is_empty(), "threshold {threshold:.3e}:\n{}", failures.join("\n"));
}

#[test]
fn lambert() {
    check(|m| matches!(m, Model::Lambert));
}

#[test]
fn realistic_phong() {
    check(|m| matches!(m, Model::Phong(_)));
}

#[test]
fn torrance_sparrow() {
    check(|m| matches!(m, Model::TsPlastic(_) | Model::TsMetal(_)));
}

#[test]
fn disney() {
    check(|m| matches!(m, Model::DisneyAll(..) | Model::DisneyDefault(_) | Model::DisneyMetal(_)));
}

#[test]
fn fmbrdf() {
    check(|m| matches!(m, Model::Fmbrdf(..)));
}

#[test]
fn trait_default() {
    check(|m| matches!(m, Model::TraitDefault(_)));
}

#[test]
fn table_has_at_least_four_configurations_per_model() {
    let count = |f: fn(&Model) -> bool| CASES.iter().filter(|c| f(&c.model)).count();
    assert!(count(|m| matches!(m, Model::Lambert)) >= 4);
    assert!(count(|m| matches!(m, Model::Phong(_))) >= 4);
    assert!(count(|m| matches!(m, Model::TsPlastic(_) | Model::TsMetal(_))) >= 4);
    assert!(count(|m| matches!(m, Model::DisneyAll(..) | Model::DisneyMetal(_))) >= 4);
    assert!(count(|m| matches!(m, Model::Fmbrdf(..))) >= 4);
}

/// A deliberately wrong sampler: draws from `draw`, reports `claim`'s pdf, and drops a fraction
/// `drop` of its samples (u0 below it) while the pdf does not say so.
struct Wrong<A, B> {
    draw: A,
    claim: B,
    drop: f64,
}

impl<A: Brdf<f64>, B: Brdf<f64>> Brdf<f64> for Wrong<A, B> {
    fn eval(&self, l: [f64; 3], v: [f64; 3]) -> Rgb<f64> {
        self.claim.eval(l, v)
    }
    fn name(&self) -> &'static str {
        "wrong"
    }
    fn sample(&self, v: [f64; 3], u: [f64; 2]) -> Option<BrdfSample<f64>> {
        if u[0] < self.drop {
            return None;
        }
        let u0 = (u[0] - self.drop) / (1.0 - self.drop);
        self.draw.sample(v, [u0, u[1]])
    }
    fn pdf(&self, v: [f64; 3], l: [f64; 3]) -> f64 {
        self.claim.pdf(v, l)
    }
}

/// The test has power: it rejects a sampler whose GGX roughness is off by 3 %, one whose lobe
/// probabilities are off by 2 points (a TS plastic sampled as if its F0 were 0.06), one that
/// silently loses 1 % of its samples, and Phong with the exponent off by 5 %.
#[test]
fn negative_controls_are_rejected() {
    let threshold = sidak_threshold(SIGNIFICANCE, CASES.len());
    let ts = |r: f64, f0: f64| {
        TorranceSparrow::new(TorranceSparrowParams {
            roughness: r,
            diffuse: [0.5, 0.4, 0.3],
            f0: [f0; 3],
        })
    };
    let phong = |n: f64| {
        RealisticPhong::new(RealisticPhongParams { kd: [0.3; 3], ks: [0.6; 3], exponent: n })
    };
    let v = dir_deg(45.0);
    let cfg = Chi2Config { seed: 99, ..Chi2Config::default() };
    let outcomes = [
        (
            "roughness 0.31 vs 0.30",
            chi2_test(&Wrong { draw: ts(0.31, 0.04), claim: ts(0.3, 0.04), drop: 0.0 }, v, cfg),
        ),
        (
            "F0 0.06 vs 0.04",
            chi2_test(&Wrong { draw: ts(0.3, 0.06), claim: ts(0.3, 0.04), drop: 0.0 }, v, cfg),
        ),
        (
            "1 % lost",
            chi2_test(&Wrong { draw: ts(0.3, 0.04), claim: ts(0.3, 0.04), drop: 0.01 }, v, cfg),
        ),
        (
            "N 257 vs 245",
            chi2_test(&Wrong { draw: phong(257.0), claim: phong(245.0), drop: 0.0 }, v, cfg),
        ),
    ];
    for (what, o) in outcomes {
        eprintln!(
            "negative control {what}: chi2 {:.1} dof {} p {:.3e}",
            o.statistic, o.dof, o.p_value
        );
        assert!(o.p_value < threshold, "{what} passed: {o:?}");
    }
    // The same construction with the right parameters passes.
    let o = chi2_test(&Wrong { draw: ts(0.3, 0.04), claim: ts(0.3, 0.04), drop: 0.0 }, v, cfg);
    assert!(o.p_value >= threshold, "{o:?}");
}

/// Q(a, x) against closed forms: integer a, e^-x sum_{k<a} x^k / k!; half-integer a,
/// erfc(sqrt x) + e^-x sum_{k<n} x^(k+1/2) / Gamma(k + 3/2) (values computed in Python from
/// those sums); and the p-value of a chi^2 at its mean is near one half for large dof.
#[test]
fn regularized_gamma_matches_closed_forms() {
    use common::chi2::{gamma_q, ln_gamma};
    let cases = [
        (1.0, 2.0, (-2.0_f64).exp()),
        (5.0, 5.0, 0.440_493_285_065_212_4),
        (100.0, 110.0, 0.158_278_670_060_091_16),
        (300.0, 280.0, 0.877_392_717_328_782_1),
        (0.5, 1.0, 0.157_299_207_050_285_13),
        (2.5, 0.1, 0.999_113_861_211_187_6),
        (150.5, 120.0, 0.995_970_912_232_012_1),
    ];
    for (a, x, q) in cases {
        let got = gamma_q(a, x);
        assert!((got - q).abs() < 1e-12 * q.max(1e-3), "Q({a}, {x}) = {got}, expected {q}");
    }
    assert!((ln_gamma(0.5) - std::f64::consts::PI.sqrt().ln()).abs() < 1e-14);
    assert!((ln_gamma(101.0) - (1..=100).map(|k| (k as f64).ln()).sum::<f64>()).abs() < 1e-10);
    assert_eq!(gamma_q(3.0, 0.0), 1.0);
    let p = gamma_q(500.0, 500.0);
    assert!((p - 0.5).abs() < 0.02, "{p}");
    assert!((sidak_threshold(0.01, 1) - 0.01).abs() < 1e-15);
}
