//! The three products of a training step's hidden layer, [batch, w] by [w, w], in f32 and in
//! each reduced precision this CPU runs natively, on every rayon thread: the forward product
//! (bias and ReLU fused), the input gradient (through the transposed weight) and the weight
//! gradient (the transposed activations by the upstream gradient, summed over the batch).
//!
//! The precisions are timed in alternation, one call each per round, 41 rounds after 5
//! warm-up rounds, so that a shared host's drifting speed falls on both alike: printed are the
//! f32 rate (median GFLOP/s) and each precision's median time ratio to f32 over the rounds.
//! The f16 weight gradient is timed through `f16dot::matmul_f16` itself (`matmul` keeps it f32).
//!
//! `cargo run --release -p cpu-kernels --features x86-v4 --example product_rates [batch] [w]`

use cpu_kernels::{Epilogue, MatRef, Precision, f16dot, matmul};
use std::time::Instant;

type Call<'a> = Box<dyn FnMut() + 'a>;

fn main() {
    let args: Vec<usize> = std::env::args().skip(1).filter_map(|a| a.parse().ok()).collect();
    let (batch, w) = (args.first().copied().unwrap_or(8192), args.get(1).copied().unwrap_or(128));
    let x: Vec<f32> = (0..batch * w).map(|i| ((i * 7919 % 1000) as f32 - 500.0) * 1e-3).collect();
    let dy: Vec<f32> = (0..batch * w).map(|i| ((i * 104729 % 977) as f32 - 488.0) * 1e-7).collect();
    let wt: Vec<f32> = (0..w * w).map(|i| ((i * 31 % 211) as f32 - 105.0) * 1e-3).collect();
    let bias = vec![0.01f32; w];
    let mut outs: Vec<Vec<f32>> = (0..3).map(|_| vec![0f32; batch * w]).collect();
    let row = |p: &Vec<f32>, cols: usize| MatRef { ptr: p.as_ptr(), rs: cols as isize, cs: 1 };
    let tr = |p: &Vec<f32>, cols: usize| MatRef { ptr: p.as_ptr(), rs: 1, cs: cols as isize };
    let mut precisions = vec![("f32", Precision::F32)];
    if cpu_kernels::bf16_dot_native() {
        precisions.push(("bf16", Precision::Bf16 { amx: true }));
    }
    if f16dot::f16_native() {
        precisions.push(("f16", Precision::F16));
    }
    let ep = Epilogue { bias: Some(&bias), relu: true };
    let flop = 2.0 * (batch * w * w) as f64;
    for product in ["forward", "input gradient", "weight gradient"] {
        let mut calls: Vec<(&str, Call)> = Vec::new();
        for (&(name, p), out) in precisions.iter().zip(outs.iter_mut()) {
            let o = out.as_mut_ptr();
            let (x, dy, wt) = (&x, &dy, &wt);
            // SAFETY (every call): the views address the vectors with their shapes.
            let call: Call = match product {
                "forward" => Box::new(move || unsafe {
                    matmul(batch, w, w, row(x, w), row(wt, w), o, ep, p)
                }),
                "input gradient" => Box::new(move || unsafe {
                    matmul(batch, w, w, row(dy, w), tr(wt, w), o, Epilogue::NONE, p)
                }),
                _ if p == Precision::F16 => Box::new(move || unsafe {
                    f16dot::matmul_f16(w, w, batch, tr(x, w), row(dy, w), o, Epilogue::NONE)
                }),
                _ => Box::new(move || unsafe {
                    matmul(w, w, batch, tr(x, w), row(dy, w), o, Epilogue::NONE, p)
                }),
            };
            calls.push((name, call));
        }
        let mut times = vec![Vec::new(); calls.len()];
        for round in 0..46 {
            for (c, (_, call)) in calls.iter_mut().enumerate() {
                let t = Instant::now();
                call();
                if round >= 5 {
                    times[c].push(t.elapsed().as_secs_f64());
                }
            }
        }
        let median = |v: &mut Vec<f64>| {
            v.sort_by(f64::total_cmp);
            v[v.len() / 2]
        };
        let base = times[0].clone();
        let mut line =
            format!("{product:>15}: f32 {:6.1} GFLOP/s", flop / median(&mut base.clone()) / 1e9);
        for (c, (name, _)) in calls.iter().enumerate().skip(1) {
            let mut ratios: Vec<f64> = times[c].iter().zip(&base).map(|(t, b)| t / b).collect();
            line += &format!(", {name} / f32 {:.3}x the time", median(&mut ratios));
        }
        println!("{line}");
    }
}
