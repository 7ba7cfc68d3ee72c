//! Development cross-check against NVIDIA's flip-evaluator (not part of CI): writes this crate's
//! HDR-FLIP maps of the deterministic test pairs to `/tmp/flip_rust_*.f32`, and compares them
//! with `/tmp/flip_ref_*.f32` written by `devtools/reference_values.py` when those exist.

use metrics::testimg::hdr_pair;
use metrics::{FlipConfig, hdr_flip_with};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    for (w, h, seed, gain) in
        [(24, 17, 5, 4.0), (40, 31, 9, 4.0), (33, 27, 2, 300.0), (160, 120, 21, 3000.0)]
    {
        let (r, t) = hdr_pair(w, h, seed, gain);
        let res = hdr_flip_with(&t, &r, None, &FlipConfig::default())?;
        let bytes: Vec<u8> = res.map.iter().flat_map(|v| v.to_le_bytes()).collect();
        std::fs::write(format!("/tmp/flip_rust_{w}x{h}_{seed}.f32"), bytes)?;
        let Ok(raw) = std::fs::read(format!("/tmp/flip_ref_{w}x{h}_{seed}.f32")) else {
            println!("{w}x{h} seed {seed}: mean {} (no reference file)", res.mean);
            continue;
        };
        let refmap: Vec<f32> =
            raw.chunks_exact(4).map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect();
        let max_diff = refmap.iter().zip(&res.map).map(|(a, b)| (a - b).abs()).fold(0.0, f32::max);
        let ref_mean = refmap.iter().map(|v| *v as f64).sum::<f64>() / refmap.len() as f64;
        println!(
            "{w}x{h} seed {seed}: mean {} vs reference {} (diff {:.2e}), max per-pixel diff {:.2e}",
            res.mean,
            ref_mean,
            (res.mean - ref_mean).abs(),
            max_diff
        );
    }
    Ok(())
}
