//! Auto-vectorised loops on the CPU's wider vectors without a build for one CPU: the workspace
//! is compiled for baseline x86-64 (SSE2), so a loop LLVM vectorises runs 4 `f32` (2 `f64`) a
//! step; [`with_avx2`] runs the same code compiled with AVX2 (8 and 4) where the CPU has it.
//!
//! The same operations in the same order, so the same bits: AVX2 alone adds no fused
//! multiply-add, and Rust never contracts `a * b + c` into one.

/// `f()`, compiled with AVX2 enabled where the CPU has it (checked once per call: a cheap,
/// cached test). Mark the function doing the work `#[inline(always)]`, so that it is compiled
/// into this context rather than called in the baseline one.
#[inline(always)]
pub fn with_avx2<R>(f: impl FnOnce() -> R) -> R {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2 (checked just above).
        return unsafe { avx2(f) };
    }
    f()
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn avx2<R>(f: impl FnOnce() -> R) -> R {
    f()
}

#[cfg(test)]
mod tests {
    use super::with_avx2;

    /// A reduction whose order would show: the same bits on either path.
    #[test]
    fn the_same_bits_as_the_baseline_loop() {
        let x: Vec<f32> = (0..1000).map(|i| (i as f32 * 0.37).sin()).collect();
        let y: Vec<f32> = (0..1000).map(|i| (i as f32 * 0.11).cos()).collect();
        let run = || -> Vec<f32> {
            let mut acc = vec![0.0f32; x.len()];
            for k in [0.5f32, -1.25, 3.0] {
                for ((a, p), q) in acc.iter_mut().zip(&x).zip(&y) {
                    *a += k * p * q;
                }
            }
            acc
        };
        let wide = with_avx2(run);
        let base = run();
        assert!(wide.iter().zip(&base).all(|(a, b)| a.to_bits() == b.to_bits()));
    }
}
