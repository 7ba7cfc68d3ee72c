//! The CPU matrix-product kernels of the neural models' linear layers, on plain strided
//! matrices (no tensor library): `brdf-neural` hands them burn-flex's buffers through a burn
//! backend extension (`brdf_neural::linear_op`), so burn itself stays unpatched.
//!
//! One entry point, [`matmul`]: `out = lhs rhs`, then an [`Epilogue`] (a bias per column, then
//! optionally a ReLU), for f32 matrices with any strides, written into an m x n row-major buffer
//! that may start uninitialised. It picks, in order:
//!
//! | path | when | module |
//! | --- | --- | --- |
//! | bf16 operands, f32 sums (AMX tiles, else `vdpbf16ps`, else emulated) | [`Precision::Bf16`] (`amx`), n >= 16, k >= 8, m n k >= 2^18 | [`bf16dot`], [`amx`] |
//! | scaled binary16 operands, binary16 sums over runs of 64 k, f32 over runs (`vfmadd231ph`, else emulated) | [`Precision::F16`], the same sizes, except a long k into a small output (weight gradients stay f32) | [`f16dot`] |
//! | f32, k summed in blocks in parallel | a long k (>= 8,192) into a small output (<= 256 x 256): weight gradients | [`split_k`] |
//! | f32 gemm in blocks of rows on every thread, the epilogue applied while the block is in cache | an epilogue, or at least two blocks of rows (2,048 rows at 128 columns); n >= 16 | [`gemm_f32`] |
//! | f32 gemm (the `gemm` crate, as burn-flex calls it) | everything else | [`gemm_f32`] |
//!
//! A product's value depends on its operands, shape and precision only, never on the thread
//! count: the f32 and bf16 split-k's parts depend on k alone, and gemm and the bf16 kernels'
//! rows parallelise over the output, not over k. The epilogue is applied after the sum with the
//! same operations per element as the unfused layer ([`epilogue`]), so `matmul` with a bias and
//! a ReLU equals `matmul` without them followed by the broadcast add and the ReLU, to the bit.
//!
//! The precision is an argument of every call, and with it whether a bf16 product takes the
//! AMX tiles where the machine has them: nothing here is per thread or per process.

extern crate alloc;

#[cfg(all(target_arch = "x86_64", target_os = "linux"))]
pub mod amx;
pub mod bf16dot;
pub mod elementwise;
pub mod epilogue;
pub mod f16dot;
#[cfg(target_arch = "x86_64")]
mod f16dot_x86;
pub mod gemm_f32;
pub mod split_k;

pub use bf16dot::{
    MatRef, bf16_amx_available, bf16_dot_native, bf16_dot_outpaces_f32, emulated_row_major,
    round_to_bf16,
};
pub use epilogue::Epilogue;

/// The precision of an f32 matrix product.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Precision {
    /// f32 operands, f32 sums (the default).
    #[default]
    F32,
    /// Operands rounded to bf16 (round to nearest even), products summed in f32: PyTorch's
    /// `torch.set_float32_matmul_precision("medium")` on the CPU. `amx`: on Intel's AMX tiles
    /// where the CPU and the OS allow them ([`bf16_amx_available`]), else on the AVX512-BF16
    /// kernel; the two sum in different orders, so their values differ in the last bits.
    Bf16 {
        /// Take the AMX tiles where they are available.
        amx: bool,
    },
    /// Operands scaled by powers of two and rounded to binary16, products summed in binary16
    /// over runs of [`f16dot::RUN`] k, the runs in f32 ([`f16dot`]): on AVX512-FP16, twice the
    /// multiply-adds of f32 per instruction; emulated elsewhere. Products that [`f16dot::parts`]
    /// would split over k (weight gradients) stay f32: their operands' scaling and conversion,
    /// two more passes over megabytes, cost more than the faster products save
    /// (`examples/product_rates.rs`).
    F16,
}

/// Whether an m x k by k x n product in [`Precision::Bf16`] (or [`Precision::F16`]) takes the
/// bf16 (f16) kernels: products
/// that gain nothing (narrow outputs such as a 3-channel head, a short k, small products) stay
/// f32.
pub fn takes_bf16(m: usize, n: usize, k: usize) -> bool {
    n >= 16 && k >= 8 && m.saturating_mul(n).saturating_mul(k) >= 1 << 18
}

/// `out = epilogue(lhs rhs)`: lhs m x k, rhs k x n (any strides), `out` m x n row-major, the
/// epilogue's bias (n values) added to every row, then its ReLU. Every element of `out` is
/// written and none is read.
///
/// # Safety
/// `lhs` and `rhs` address valid m x k and k x n f32 matrices with their strides, `out` m n
/// writable floats that nothing else touches during the call.
///
/// # Panics
/// If the epilogue's bias does not hold n values.
#[allow(clippy::too_many_arguments)]
pub unsafe fn matmul(
    m: usize,
    n: usize,
    k: usize,
    lhs: MatRef,
    rhs: MatRef,
    out: *mut f32,
    epilogue: Epilogue,
    precision: Precision,
) {
    if m == 0 || n == 0 {
        return;
    }
    if let Some(b) = epilogue.bias {
        assert_eq!(b.len(), n, "cpu_kernels::matmul: bias of {} values for {n} columns", b.len());
    }
    if let Precision::Bf16 { amx } = precision
        && takes_bf16(m, n, k)
    {
        // SAFETY: the caller's contract, which is the kernel's.
        unsafe { bf16dot::matmul_bf16dot(m, n, k, lhs, rhs, out, epilogue, amx) };
        return;
    }
    // The f16 path where it gains: not the split-k products (see `Precision::F16`).
    if precision == Precision::F16 && takes_bf16(m, n, k) && f16dot::parts(m, n, k).0 == 1 {
        // SAFETY: the caller's contract, which is the kernel's.
        unsafe { f16dot::matmul_f16(m, n, k, lhs, rhs, out, epilogue) };
        return;
    }
    let blocks = split_k::split_k_blocks(m, n, k);
    if blocks > 1 {
        let op = |r: MatRef| split_k::Operand { ptr: r.ptr, rs: r.rs, cs: r.cs };
        // SAFETY: the caller's contract, which is the kernel's.
        unsafe { split_k::matmul_split_k(m, n, k, blocks, op(lhs), op(rhs), out) };
        // SAFETY: `out` holds the m x n product just written.
        unsafe { epilogue.apply_rows(m, n, out) };
        return;
    }
    if n >= 16 && k > 0 && (epilogue.is_some() || gemm_f32::row_blocks(m, n) >= 2) {
        // SAFETY: the caller's contract, which is the kernel's.
        unsafe { gemm_f32::gemm_by_rows(m, n, k, lhs, rhs, epilogue, out) };
        return;
    }
    // SAFETY: the caller's contract, which is the kernel's.
    unsafe { gemm_f32::gemm(m, n, k, lhs, rhs, out) };
    // SAFETY: `out` holds the m x n product just written.
    unsafe { epilogue.apply_rows(m, n, out) };
}

/// [`matmul`] on row-major slices into a new vector: `a` m x k, `b` k x n, then `epilogue`.
///
/// # Panics
/// If the slice lengths do not match the shapes.
pub fn matmul_row_major(
    m: usize,
    n: usize,
    k: usize,
    a: &[f32],
    b: &[f32],
    epilogue: Epilogue,
    precision: Precision,
) -> Vec<f32> {
    assert!(a.len() == m * k && b.len() == k * n, "matmul_row_major: shapes");
    let mut out = vec![0f32; m * n];
    let lhs = MatRef { ptr: a.as_ptr(), rs: k as isize, cs: 1 };
    let rhs = MatRef { ptr: b.as_ptr(), rs: n as isize, cs: 1 };
    // SAFETY: the views address exactly the checked slices; `out` holds m n floats.
    unsafe { matmul(m, n, k, lhs, rhs, out.as_mut_ptr(), epilogue, precision) };
    out
}
