//! Run time and results of the two energy estimators on one model (a Torrance-Sparrow BRDF that
//! is not energy-conserving at grazing light): `cargo run -p metrics --example energy_timing --
//! [pairs] [samples]` (defaults: 2,000 pairs, the paper's 20,000 samples per pair).

use metrics::energy::{EnergyConfig, EnergyPair, Estimator, energy_conservation};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<usize> = std::env::args().skip(1).filter_map(|a| a.parse().ok()).collect();
    let n_pairs = args.first().copied().unwrap_or(2_000);
    let samples = args.get(1).copied().unwrap_or(20_000);
    let brdf = brdf_analytic::TorranceSparrow::new(brdf_analytic::TorranceSparrowParams {
        roughness: 0.6,
        diffuse: [1.0, 0.9, 0.5],
        f0: [0.9; 3],
    });
    // Light directions uniform in solid angle over the upper hemisphere (golden-ratio lattice).
    let pairs: Vec<EnergyPair> = (0..n_pairs)
        .map(|i| {
            let z = 1.0 - (i as f64 + 0.5) / n_pairs as f64;
            let phi = std::f64::consts::TAU * (i as f64 * 0.618_033_988_749_895).fract();
            let r = (1.0 - z * z).sqrt();
            EnergyPair { point: 0, l: [(r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32] }
        })
        .collect();
    let mut reports = Vec::new();
    for (name, estimator) in
        [("paper MC", Estimator::MonteCarlo { samples }), ("Sobol RQMC", Estimator::fast())]
    {
        let cfg = EnergyConfig { estimator, seed: 1, progress: true };
        let rep = energy_conservation(&brdf, &pairs, &cfg)?;
        let max_se = rep.pairs.iter().flat_map(|p| p.std_error).fold(0.0, f64::max);
        let mean_se =
            rep.pairs.iter().flat_map(|p| p.std_error).sum::<f64>() / (3 * n_pairs) as f64;
        println!(
            "{name:>10}: {n_pairs} pairs, {:.3e} evaluations, {:.2} s; above 1: {:.2} %, median of \
             those {:?}; std error mean {mean_se:.2e}, max {max_se:.2e}",
            rep.evaluations as f64, rep.seconds, rep.percent_above_one, rep.median_above_one
        );
        reports.push(rep);
    }
    // Agreement: per pair and channel, |E_mc - E_qmc| in units of the combined error bar.
    let z: Vec<f64> = reports[0]
        .pairs
        .iter()
        .zip(&reports[1].pairs)
        .flat_map(|(a, b)| {
            (0..3).map(move |c| {
                let s = (a.std_error[c].powi(2) + b.std_error[c].powi(2)).sqrt().max(1e-12);
                (a.energy[c] - b.energy[c]).abs() / s
            })
        })
        .collect();
    let beyond3 = z.iter().filter(|v| **v > 3.0).count() as f64 / z.len() as f64;
    println!(
        "agreement: {:.2} % of pair-channels differ by more than 3 combined error bars",
        100.0 * beyond3
    );
    // Verdicts that the MC noise alone explains: MC says above 1 but the QMC estimate is clearly below.
    let flips = reports[0]
        .pairs
        .iter()
        .zip(&reports[1].pairs)
        .filter(|(a, b)| {
            let va = a.energy.iter().any(|e| *e > 1.0);
            let vb = b.energy.iter().any(|e| *e > 1.0);
            va != vb
        })
        .count();
    println!("pairs with different verdicts: {flips} of {n_pairs}");
    Ok(())
}
