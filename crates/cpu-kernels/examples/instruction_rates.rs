//! The peak rates of the instructions the CPU kernels' products are built on, on one core: the
//! f32 FMA (`vfmadd231ps` on zmm, what the f32 gemm runs), the binary16 FMA (`vfmadd231ph`, the
//! f16 kernel's, where the CPU has AVX512-FP16) and the bf16 dot product (`vdpbf16ps` on zmm,
//! the AVX512-BF16 kernel's). Each issues 16 independent accumulator
//! chains in a loop, so the figure is the instruction's throughput, not its latency.
//!
//! Whether bf16 products pay on a CPU without AMX comes down to the ratio printed last: a
//! `vdpbf16ps` does twice the multiply-adds of an f32 FMA, so bf16 gains only where it issues at
//! more than half the FMA's rate (`cpu_kernels::bf16_dot_outpaces_f32`, benches/README.md).
//!
//! `cargo run --release -p cpu-kernels --example instruction_rates`

use std::time::Instant;

#[cfg(target_arch = "x86_64")]
mod x86 {
    use core::arch::x86_64::*;

    /// `iters` rounds of 16 independent `vfmadd231ps` zmm; returns a sum that keeps them live.
    #[target_feature(enable = "avx512f")]
    pub unsafe fn fma(iters: u64) -> f32 {
        let mut acc = [_mm512_setzero_ps(); 16];
        let (a, b) = (_mm512_set1_ps(1.0001), _mm512_set1_ps(0.9999));
        for _ in 0..iters {
            for x in acc.iter_mut() {
                *x = _mm512_fmadd_ps(*x, a, b);
            }
            // SAFETY: an empty block; it only stops the compiler from folding the loop.
            unsafe { core::arch::asm!("", options(nomem, nostack)) };
        }
        _mm512_reduce_add_ps(acc.iter().fold(_mm512_setzero_ps(), |s, x| _mm512_add_ps(s, *x)))
    }

    /// `iters` rounds of 16 independent `vfmadd231ph` zmm (binary16, inline assembly: Rust
    /// has no stable binary16 intrinsics).
    #[target_feature(enable = "avx512f,avx512bw,avx512vl,avx512fp16")]
    pub unsafe fn fma_f16(iters: u64) -> f32 {
        let mut acc = [_mm512_setzero_si512(); 16];
        // binary16 bits of 1.0 and 0.5 in every lane.
        let (a, b) = (_mm512_set1_epi16(0x3c00), _mm512_set1_epi16(0x3800));
        for _ in 0..iters {
            for x in acc.iter_mut() {
                // SAFETY: register operands only; AVX512-FP16 is enabled for this function.
                unsafe {
                    core::arch::asm!(
                        "vfmadd231ph {x}, {a}, {b}",
                        x = inout(zmm_reg) *x,
                        a = in(zmm_reg) a,
                        b = in(zmm_reg) b,
                        options(pure, nomem, nostack),
                    )
                };
            }
        }
        let sum = acc.iter().fold(_mm512_setzero_si512(), |s, x| _mm512_xor_si512(s, *x));
        _mm512_reduce_add_epi32(sum) as f32
    }

    /// `iters` rounds of 16 independent `vdpbf16ps` zmm.
    #[target_feature(enable = "avx512f,avx512bw,avx512bf16")]
    pub unsafe fn dpbf16(iters: u64) -> f32 {
        let mut acc = [_mm512_setzero_ps(); 16];
        // SAFETY: both are 512-bit vectors; the bits are bf16 pairs of 1.0.
        let ones: __m512bh = unsafe { core::mem::transmute(_mm512_set1_epi32(0x3f80_3f80)) };
        for _ in 0..iters {
            for x in acc.iter_mut() {
                *x = _mm512_dpbf16_ps(*x, ones, ones);
            }
            // SAFETY: as above.
            unsafe { core::arch::asm!("", options(nomem, nostack)) };
        }
        _mm512_reduce_add_ps(acc.iter().fold(_mm512_setzero_ps(), |s, x| _mm512_add_ps(s, *x)))
    }
}

/// Instructions a second of `run(iters)`, best of three.
fn rate(run: impl Fn(u64) -> f32, iters: u64) -> f64 {
    (0..3)
        .map(|_| {
            let t = Instant::now();
            std::hint::black_box(run(iters));
            (iters * 16) as f64 / t.elapsed().as_secs_f64()
        })
        .fold(0.0, f64::max)
}

fn main() {
    #[cfg(target_arch = "x86_64")]
    {
        if !std::is_x86_feature_detected!("avx512f") {
            println!("no AVX-512 on this CPU: nothing to measure");
            return;
        }
        let iters = 20_000_000;
        // SAFETY: AVX-512F was detected above.
        let fma = rate(|n| unsafe { x86::fma(n) }, iters);
        println!(
            "f32 FMA (zmm): {:.2} G/s, {:.1} GFLOP/s on one core",
            fma / 1e9,
            fma * 32.0 / 1e9
        );
        if cpu_kernels::f16dot::f16_native() {
            // SAFETY: AVX512-FP16 (with F, BW and VL) was detected by `f16_native`.
            let ph = rate(|n| unsafe { x86::fma_f16(n) }, iters);
            println!(
                "binary16 FMA (zmm): {:.2} G/s, {:.1} GFLOP/s on one core; binary16 / f32 \
                 multiply-add rate {:.2}x",
                ph / 1e9,
                ph * 64.0 / 1e9,
                ph * 2.0 / fma
            );
        }
        if !cpu_kernels::bf16_dot_native() {
            println!("no AVX512-BF16 on this CPU: bf16 products are emulated");
            return;
        }
        // SAFETY: AVX512-BF16 (with F and BW) was detected by `bf16_dot_native`.
        let dp = rate(|n| unsafe { x86::dpbf16(n) }, iters);
        println!("bf16 dot (zmm): {:.2} G/s, {:.1} GFLOP/s on one core", dp / 1e9, dp * 64.0 / 1e9);
        println!(
            "bf16 / f32 multiply-add rate: {:.2}x (bf16 default here: {})",
            dp * 2.0 / fma,
            cpu_kernels::bf16_dot_outpaces_f32() || cpu_kernels::bf16_amx_available()
        );
    }
    #[cfg(not(target_arch = "x86_64"))]
    println!("not x86-64: nothing to measure");
}
