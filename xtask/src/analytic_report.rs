//! `cargo xtask analytic-report`: a characterisation of every analytic BRDF at its default
//! parameters: directional albedo against incidence angle (cosine-weighted Monte Carlo with a
//! standard error), reciprocity error and evaluation speed. Written as Markdown to stdout and,
//! atomically, to a file.

use brdf_analytic::albedo::{cosine_sample, directional_albedo};
use brdf_analytic::*;
use std::fmt::Write as _;
use std::time::Instant;
use stdx::rng::SplitMix64;

/// Options of the report.
pub struct Options {
    /// Monte Carlo samples per albedo estimate.
    pub samples: usize,
    /// Random pairs for the reciprocity error.
    pub pairs: usize,
    /// Seed of every random number.
    pub seed: u64,
}

/// The models at their default parameters, f64 (reference precision).
fn models() -> Vec<Box<dyn Brdf<f64>>> {
    vec![
        Box::new(Lambert::new(LambertParams::default())),
        Box::new(RealisticPhong::new(RealisticPhongParams::default())),
        Box::new(TorranceSparrow::new(TorranceSparrowParams::default())),
        Box::new(Disney::new(DisneyParams::default())),
        Box::new(Fmbrdf::new(FmbrdfParams::default())),
    ]
}

const THETAS_DEG: [f64; 6] = [0.0, 30.0, 60.0, 75.0, 85.0, 89.0];

/// Builds the report as Markdown.
pub fn report(opts: &Options) -> String {
    let mut md = String::new();
    let _ = writeln!(md, "# Analytic BRDFs at default parameters\n");
    let _ = writeln!(
        md,
        "Directional albedo a(theta_l) = int f cos(theta_v) dv, mean of RGB, cosine-weighted Monte \
         Carlo with {} samples (+- one standard error); seed {}.\n",
        opts.samples, opts.seed
    );
    let mut header = "| model |".to_string();
    let mut rule = "| --- |".to_string();
    for t in THETAS_DEG {
        let _ = write!(header, " theta_l = {t} deg |");
        rule.push_str(" --- |");
    }
    let _ = writeln!(md, "{header}\n{rule}");
    let all = models();
    for (k, m) in all.iter().enumerate() {
        eprintln!("[{}/{}] directional albedo of {}", k + 1, all.len(), m.name());
        let mut row = format!("| {} |", m.name());
        for (i, t) in THETAS_DEG.iter().enumerate() {
            let (s, c) = t.to_radians().sin_cos();
            let e = directional_albedo(m.as_ref(), [s, 0.0, c], opts.samples, opts.seed + i as u64);
            let mean = e.mean.iter().sum::<f64>() / 3.0;
            let se = e.std_error.iter().sum::<f64>() / 3.0;
            let _ = write!(row, " {mean:.4} +- {se:.4} |");
        }
        let _ = writeln!(md, "{row}");
    }
    let _ = writeln!(
        md,
        "\nReciprocity and speed over {} random upper-hemisphere pairs: relative RMSE of \
         f(l, v) - f(v, l) (f64), and single-thread f32 evaluations per second.\n",
        opts.pairs
    );
    let _ = writeln!(
        md,
        "| model | reciprocity rel. RMSE | evaluations / s (f32, 1 thread) |\n| --- | --- | --- |"
    );
    let mut rng = SplitMix64::new(opts.seed);
    let pairs: Vec<([f64; 3], [f64; 3])> = (0..opts.pairs)
        .map(|_| {
            let l = cosine_sample(rng.next_f64(), rng.next_f64());
            let v = cosine_sample(rng.next_f64(), rng.next_f64());
            (l, v)
        })
        .collect();
    let models32: Vec<Box<dyn Brdf<f32>>> = vec![
        Box::new(Lambert::new(LambertParams::default())),
        Box::new(RealisticPhong::new(RealisticPhongParams::default())),
        Box::new(TorranceSparrow::new(TorranceSparrowParams::default())),
        Box::new(Disney::new(DisneyParams::default())),
        Box::new(Fmbrdf::new(FmbrdfParams::default())),
    ];
    for (k, (m, m32)) in all.iter().zip(&models32).enumerate() {
        eprintln!("[{}/{}] reciprocity and speed of {}", k + 1, all.len(), m.name());
        let (mut num, mut den) = (0.0, 0.0);
        for (l, v) in &pairs {
            let (a, b) = (m.eval(*l, *v), m.eval(*v, *l));
            for c in 0..3 {
                num += (a[c] - b[c]).powi(2);
                den += (0.5 * (a[c] + b[c])).powi(2);
            }
        }
        let rel = (num / den.max(f64::MIN_POSITIVE)).sqrt();
        let l32: Vec<[f32; 3]> = pairs.iter().map(|p| p.0.map(|x| x as f32)).collect();
        let v32: Vec<[f32; 3]> = pairs.iter().map(|p| p.1.map(|x| x as f32)).collect();
        let mut out = vec![[0.0_f32; 3]; pairs.len()];
        let start = Instant::now();
        eval_batch(m32.as_ref(), &l32, &v32, &mut out);
        let rate = pairs.len() as f64 / start.elapsed().as_secs_f64();
        std::hint::black_box(&out);
        let _ = writeln!(md, "| {} | {rel:.3e} | {:.1} M |", m.name(), rate / 1e6);
    }
    md
}
