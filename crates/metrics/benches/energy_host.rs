//! The host's share of the paper's energy protocol (20,000 cosine-weighted samples a pair)
//! for a model that runs elsewhere: a stand-in [`SurfaceBrdf`] that is not `parallel` (as a
//! model on a GPU) and costs next to nothing, so the time is the sampling, the batch assembly
//! and the sums. `ENERGY_BENCH_BATCH` (default 262144, `experiments`' GPU pass) is the model's
//! preferred batch: 13 pairs a call at 2^18, one at 2^15. The summary line gives ns per
//! evaluation; at 10^9 evaluations (the paper's 50,000 pairs) a nanosecond costs a second.
//!
//! `cargo bench -p metrics --bench energy_host`

use brdf_analytic::SurfaceBrdf;
use criterion::{Criterion, criterion_group, criterion_main};
use metrics::energy::{EnergyConfig, EnergyPair, Estimator, energy_conservation};
use std::time::Instant;

/// f = 0.3 cos(theta_v) / pi per channel, evaluated on one thread.
struct Remote(usize);

impl SurfaceBrdf for Remote {
    fn eval_points(&self, _: &[u32], _: &[[f32; 3]], v: &[[f32; 3]], out: &mut [[f32; 3]]) {
        for (o, v) in out.iter_mut().zip(v) {
            *o = [v[2] * 0.3 / std::f32::consts::PI; 3];
        }
    }

    fn preferred_batch(&self) -> usize {
        self.0
    }

    fn parallel(&self) -> bool {
        false
    }
}

fn energy_host(c: &mut Criterion) {
    let batch =
        std::env::var("ENERGY_BENCH_BATCH").ok().and_then(|s| s.parse().ok()).unwrap_or(1 << 18);
    let pairs: Vec<EnergyPair> =
        (0..104).map(|i| EnergyPair { point: i, l: [0.0, 0.6, 0.8] }).collect();
    let config = EnergyConfig {
        estimator: Estimator::MonteCarlo { samples: 20_000 },
        seed: 1,
        progress: false,
    };
    let model = Remote(batch);
    let mut group = c.benchmark_group("energy_host");
    group.sample_size(10);
    group.bench_function(format!("paper protocol, 104 pairs, batch {batch}"), |b| {
        b.iter(|| energy_conservation(&model, &pairs, &config).unwrap())
    });
    group.finish();
    let t = Instant::now();
    let r = energy_conservation(&model, &pairs, &config).unwrap();
    let ns = t.elapsed().as_secs_f64() * 1e9 / r.evaluations as f64;
    eprintln!(
        "{} evaluations: {ns:.1} ns each on the host ({} threads)",
        r.evaluations,
        rayon::current_num_threads()
    );
}

criterion_group!(benches, energy_host);
criterion_main!(benches);
