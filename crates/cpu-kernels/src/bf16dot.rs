//! f32 matrix products through bf16 dot products.
//!
//! The CPU counterpart of PyTorch's `torch.set_float32_matmul_precision("medium")`: both
//! operands of an f32 product are rounded to bfloat16 (round to nearest even), pairs of products
//! are summed in f32 and the output stays f32. On x86-64 with AVX512-BF16 the products run in
//! `vdpbf16ps`, which does twice the multiply-adds of an f32 FMA per instruction; elsewhere the
//! same numbers come from rounding the operands and calling the f32 gemm (slower than plain f32,
//! but the same precision, so a fit does not change its meaning with the machine).
//!
//! The caller chooses the precision per product ([`crate::Precision`], an argument of
//! [`crate::matmul`]), and so does whether the product takes the AMX tiles where they are
//! available ([`crate::amx`]); nothing here is per thread or per process.
//!
//! The kernel computes a 12 x 32 tile of the output in 24 zmm accumulators over the whole inner
//! dimension. The left operand is read as bf16 pairs (two consecutive k of one row, one u32),
//! broadcast to all lanes; the right operand is packed into panels of 32 columns, each k pair of a
//! column one u32 ("VNNI" layout). Row-contiguous left operands are converted a tile at a time
//! inside the parallel loop, the next tile's rows asked for ahead of time; the others are
//! packed once, in parallel. A product's epilogue is added to each tile of rows as it is stored.
//!
//! The operands of a training step's products are megabytes that mostly come from L3 or memory,
//! so the loops that read them ask for rows ahead (`_mm_prefetch`; what it saves:
//! benches/README.md, "the bf16 products' operands asked for ahead of time").

use crate::Epilogue;
use alloc::vec;
use alloc::vec::Vec;

/// Whether this CPU runs bf16 products natively (AVX512-BF16); otherwise they are emulated.
pub fn bf16_dot_native() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::is_x86_feature_detected!("avx512f")
            && std::is_x86_feature_detected!("avx512bw")
            && std::is_x86_feature_detected!("avx512bf16")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// Whether this CPU's AVX512-BF16 kernel is faster than its f32 gemm: on AMD's CPUs (Zen 4
/// on), whose `vdpbf16ps` does twice the multiply-adds of an f32 FMA at the same rate, yes; on
/// Intel's, no: there `vdpbf16ps` issues at a quarter of the FMA's rate, and the kernel was
/// measured at about half the f32 gemm's rate, on Xeons whose AMX tiles Linux refused and on
/// Xeons whose hypervisor hides AMX altogether (benches/README.md, "bf16 on AMX tiles" and
/// "Issue 56: bf16 products where a hypervisor hides AMX"; `examples/instruction_rates.rs`
/// measures a CPU). Other vendors are not assumed to gain either. `false` without AVX512-BF16.
pub fn bf16_dot_outpaces_f32() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        bf16_dot_native() && cpu_vendor_is_amd()
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// Whether CPUID's vendor string (leaf 0) is AMD's, "AuthenticAMD".
#[cfg(target_arch = "x86_64")]
fn cpu_vendor_is_amd() -> bool {
    let r = core::arch::x86_64::__cpuid(0);
    let mut vendor = [0u8; 12];
    vendor[0..4].copy_from_slice(&r.ebx.to_le_bytes());
    vendor[4..8].copy_from_slice(&r.edx.to_le_bytes());
    vendor[8..12].copy_from_slice(&r.ecx.to_le_bytes());
    &vendor == b"AuthenticAMD"
}

/// Whether bf16 products asked to take Intel's AMX tiles ([`crate::Precision::Bf16`] with
/// `amx`) run on them in this process: the CPU has AMX-TILE and AMX-BF16 and Linux granted the
/// tile registers ([`crate::amx`]).
pub fn bf16_amx_available() -> bool {
    #[cfg(all(target_arch = "x86_64", target_os = "linux"))]
    {
        crate::amx::amx_available()
    }
    #[cfg(not(all(target_arch = "x86_64", target_os = "linux")))]
    {
        false
    }
}

/// f32 -> bf16 bits, round to nearest even; NaN stays a quiet NaN.
#[inline]
pub fn bf16_bits(x: f32) -> u16 {
    let b = x.to_bits();
    if x.is_nan() {
        return ((b >> 16) | 0x40) as u16;
    }
    let rounding = 0x7FFF + ((b >> 16) & 1);
    (b.wrapping_add(rounding) >> 16) as u16
}

/// `x` rounded to the nearest bf16, as f32.
#[inline]
pub fn round_to_bf16(x: f32) -> f32 {
    f32::from_bits((bf16_bits(x) as u32) << 16)
}

/// Strided view of a row-major-or-not f32 matrix: element (i, j) at `ptr + i*rs + j*cs`.
#[derive(Clone, Copy)]
pub struct MatRef {
    /// Element (0, 0).
    pub ptr: *const f32,
    /// Elements from one row to the next.
    pub rs: isize,
    /// Elements from one column to the next.
    pub cs: isize,
}

// SAFETY: a MatRef is a read-only view; the caller of `matmul_bf16dot` keeps it valid.
unsafe impl Send for MatRef {}
unsafe impl Sync for MatRef {}

impl MatRef {
    /// Start of row i.
    #[inline]
    pub(crate) unsafe fn row(&self, i: usize) -> *const f32 {
        unsafe { self.ptr.offset(i as isize * self.rs) }
    }

    #[inline]
    pub(crate) unsafe fn at_ptr(&self, i: usize, j: usize) -> *const f32 {
        unsafe { self.ptr.offset(i as isize * self.rs + j as isize * self.cs) }
    }

    #[inline]
    pub(crate) unsafe fn at(&self, i: usize, j: usize) -> f32 {
        unsafe { *self.ptr.offset(i as isize * self.rs + j as isize * self.cs) }
    }
}

/// out (m x n, row-major, contiguous) = epilogue(lhs (m x k) * rhs (k x n)) with bf16
/// operands. Every element of `out` is written (it may start uninitialised). The epilogue (a
/// bias per column added in f32 after the sum, then a ReLU) goes into the AMX kernel's store
/// and the AVX512-BF16 kernel's tiles of rows; the emulated path and the split-k sums apply it
/// in one pass afterwards. `amx`: on AMX tiles where [`bf16_amx_available`] finds them,
/// else (and everywhere without them) on the AVX512-BF16 kernel or emulated.
///
/// # Safety
/// `lhs` and `rhs` must address valid m x k and k x n matrices, `out` m * n writable floats;
/// the epilogue's bias, if any, holds n values.
#[allow(clippy::too_many_arguments)]
pub unsafe fn matmul_bf16dot(
    m: usize,
    n: usize,
    k: usize,
    lhs: MatRef,
    rhs: MatRef,
    out: *mut f32,
    epilogue: Epilogue,
    amx: bool,
) {
    if m == 0 || n == 0 {
        return;
    }
    if k == 0 {
        unsafe { core::ptr::write_bytes(out, 0, m * n) };
    } else {
        #[cfg(not(all(target_arch = "x86_64", target_os = "linux")))]
        let _ = amx;
        #[cfg(all(target_arch = "x86_64", target_os = "linux"))]
        if amx && crate::amx::amx_available() {
            unsafe { crate::amx::matmul(m, n, k, lhs, rhs, out, epilogue) };
            return;
        }
        // AVX512-BF16 applies the epilogue itself, a tile of rows at a time.
        #[cfg(target_arch = "x86_64")]
        if bf16_dot_native() {
            unsafe { x86::matmul(m, n, k, lhs, rhs, out, epilogue) };
            return;
        }
        unsafe { emulated(m, n, k, lhs, rhs, core::slice::from_raw_parts_mut(out, m * n)) };
    }
    unsafe { epilogue.apply_rows(m, n, out) };
}

/// The emulated path on row-major operands (what CPUs without AVX512-BF16 run), public so
/// that tests on any machine can check it: `a` is m x k, `b` is k x n, the result m x n.
///
/// # Panics
/// If the slice lengths do not match the shapes.
pub fn emulated_row_major(m: usize, n: usize, k: usize, a: &[f32], b: &[f32]) -> Vec<f32> {
    assert!(a.len() == m * k && b.len() == k * n, "emulated_row_major: shapes");
    let mut out = vec![0f32; m * n];
    let lhs = MatRef { ptr: a.as_ptr(), rs: k as isize, cs: 1 };
    let rhs = MatRef { ptr: b.as_ptr(), rs: n as isize, cs: 1 };
    if m > 0 && n > 0 && k > 0 {
        // SAFETY: the views address exactly the checked slices.
        unsafe { emulated(m, n, k, lhs, rhs, &mut out) };
    }
    out
}

/// The reference: operands rounded to bf16, then the f32 gemm (exact products, f32 sums).
///
/// # Safety
/// As [`matmul_bf16dot`].
pub(crate) unsafe fn emulated(
    m: usize,
    n: usize,
    k: usize,
    lhs: MatRef,
    rhs: MatRef,
    out: &mut [f32],
) {
    let mut a = vec![0f32; m * k];
    let mut b = vec![0f32; k * n];
    for i in 0..m {
        for j in 0..k {
            a[i * k + j] = round_to_bf16(unsafe { lhs.at(i, j) });
        }
    }
    for i in 0..k {
        for j in 0..n {
            b[i * n + j] = round_to_bf16(unsafe { rhs.at(i, j) });
        }
    }
    unsafe {
        gemm::gemm(
            m,
            n,
            k,
            out.as_mut_ptr(),
            1,
            n as isize,
            false,
            a.as_ptr(),
            1,
            k as isize,
            b.as_ptr(),
            1,
            n as isize,
            0.0f32,
            1.0f32,
            false,
            false,
            false,
            gemm::Parallelism::None,
        )
    };
}

/// Two floats as one pair of bf16 bits, the first in the low half (the order `vdpbf16ps` pairs).
#[inline]
pub(crate) fn pair_bits(x0: f32, x1: f32) -> u32 {
    bf16_bits(x0) as u32 | ((bf16_bits(x1) as u32) << 16)
}

#[cfg(target_arch = "x86_64")]
pub(crate) mod x86 {
    use super::{Epilogue, MatRef, Vec, pair_bits, vec};
    use core::arch::x86_64::*;

    const MR: usize = 12;
    const NR: usize = 32;

    pub(crate) struct SendPtr<T>(pub(crate) *mut T);
    unsafe impl<T> Send for SendPtr<T> {}
    unsafe impl<T> Sync for SendPtr<T> {}
    impl<T> SendPtr<T> {
        pub(crate) fn get(&self) -> *mut T {
            self.0
        }
    }

    /// How the kernel reads left-operand pairs: pair p of row i at `base + i*rs + p*ps` (u32).
    #[derive(Clone, Copy)]
    struct APairs {
        base: *const u32,
        rs: usize,
        ps: usize,
    }

    /// Below this many output elements per k, a product with a long inner dimension (the weight
    /// gradient, summed over the batch) splits k over the threads instead of the rows.
    const SPLIT_K_MIN_K: usize = 2048;

    /// The epilogue goes into each tile of rows while it is in cache ([`by_rows`]), or
    /// follows the split-k sum.
    pub(super) unsafe fn matmul(
        m: usize,
        n: usize,
        k: usize,
        lhs: MatRef,
        rhs: MatRef,
        out: *mut f32,
        epilogue: Epilogue,
    ) {
        #[cfg(feature = "rayon")]
        if k >= SPLIT_K_MIN_K && m * n <= k * 16 {
            unsafe { split_k(m, n, k, lhs, rhs, out) };
            unsafe { epilogue.apply_rows(m, n, out) };
            return;
        }
        unsafe { by_rows(m, n, k, lhs, rhs, out, epilogue) }
    }

    /// Pairs per k block of the split-k path: the packed blocks of both operands stay in L2.
    const KC_PAIRS: usize = 256;

    /// Each part of k (`split_k::bf16_parts`) is summed into its own m x n partial, a block of
    /// k at a time (both operands packed per block, cache-hot), the parts in parallel; then the
    /// partials are added in part order.
    #[cfg(feature = "rayon")]
    unsafe fn split_k(m: usize, n: usize, k: usize, lhs: MatRef, rhs: MatRef, out: *mut f32) {
        use rayon::prelude::*;
        let pairs = k.div_ceil(2);
        let (parts, per) = crate::split_k::bf16_parts(pairs, 1);
        let panels = n.div_ceil(NR);
        let tiles = m.div_ceil(MR);
        let partials: Vec<Vec<f32>> = (0..parts)
            .into_par_iter()
            .map(|t| {
                let (p0, p1) = (t * per, ((t + 1) * per).min(pairs));
                let mut c = vec![0f32; m * n];
                let mut apack = Vec::new();
                let mut bpack = Vec::new();
                let mut q0 = p0;
                while q0 < p1 {
                    let q1 = (q0 + KC_PAIRS).min(p1);
                    let (k0, k1) = (2 * q0, (2 * q1).min(k));
                    let kp = q1 - q0;
                    apack.clear();
                    apack.resize(kp * m, 0u32);
                    bpack.clear();
                    bpack.resize(panels * kp * NR, 0u32);
                    for q in 0..kp {
                        // The rows PREFETCH_PAIRS pairs ahead, into L2 while this pair packs:
                        // the weight gradient's operands (activations and upstream
                        // gradients, megabytes each) mostly come from L3 or memory.
                        let ahead = k0 + 2 * (q + PREFETCH_PAIRS);
                        if ahead + 1 < k1 {
                            unsafe {
                                prefetch_row(lhs.at_ptr(0, ahead), m, lhs.rs);
                                prefetch_row(lhs.at_ptr(0, ahead + 1), m, lhs.rs);
                                prefetch_row(rhs.row(ahead), n, rhs.cs);
                                prefetch_row(rhs.row(ahead + 1), n, rhs.cs);
                            }
                        }
                        unsafe {
                            pack_a_pair(m, k0 + 2 * q, k1, lhs, apack.as_mut_ptr().add(q * m));
                            pack_b_pair(n, k0 + 2 * q, k1, kp, rhs, bpack.as_mut_ptr().add(q * NR));
                        }
                    }
                    let a_all = APairs { base: apack.as_ptr(), rs: 1, ps: m };
                    for j in 0..panels {
                        let cols = NR.min(n - j * NR);
                        let b = unsafe { bpack.as_ptr().add(j * kp * NR) };
                        for ti in 0..tiles {
                            let i0 = ti * MR;
                            let a = APairs { base: unsafe { a_all.base.add(i0) }, ..a_all };
                            let cp = unsafe { c.as_mut_ptr().add(i0 * n + j * NR) };
                            unsafe {
                                kernel_dispatch(MR.min(m - i0), kp, a, b, cp, n, cols, q0 > p0)
                            };
                        }
                    }
                    q0 = q1;
                }
                c
            })
            .collect();
        let out = SendPtr(out);
        (0..m).into_par_iter().with_min_len(16).for_each(|i| {
            let dst = unsafe { core::slice::from_raw_parts_mut(out.get().add(i * n), n) };
            dst.copy_from_slice(&partials[0][i * n..(i + 1) * n]);
            for part in &partials[1..] {
                for (d, s) in dst.iter_mut().zip(&part[i * n..(i + 1) * n]) {
                    *d += s;
                }
            }
        });
    }

    /// How many pairs of rows ahead the split-k packing asks for its operands' rows.
    const PREFETCH_PAIRS: usize = 8;

    /// Asks for the cache lines of `len` floats from `row` on, when they are contiguous
    /// (`stride` 1); nothing otherwise.
    #[inline(always)]
    unsafe fn prefetch_row(row: *const f32, len: usize, stride: isize) {
        if stride != 1 {
            return;
        }
        let mut off = 0;
        while off < len {
            unsafe { _mm_prefetch::<_MM_HINT_T1>(row.add(off) as *const i8) };
            off += 16;
        }
    }

    /// Tiles of rows in parallel, the whole k in registers; each tile's rows get the epilogue
    /// as soon as their last panel is stored.
    unsafe fn by_rows(
        m: usize,
        n: usize,
        k: usize,
        lhs: MatRef,
        rhs: MatRef,
        out: *mut f32,
        epilogue: Epilogue,
    ) {
        if let Some(b) = epilogue.bias {
            assert_eq!(b.len(), n, "bf16dot: bias of {} values for {n} columns", b.len());
        }
        let kp = k.div_ceil(2);
        let panels = n.div_ceil(NR);
        let tiles = m.div_ceil(MR);
        // Right operand: panels [panel][p][32] of pairs, zero-padded.
        let mut bpack = vec![0u32; panels * kp * NR];
        unsafe { pack_b(k, n, rhs, &mut bpack) };
        // Left operand: converted a tile at a time when its rows are contiguous, else packed.
        let row_contiguous = lhs.cs == 1;
        let apack: Vec<u32> =
            if row_contiguous { Vec::new() } else { unsafe { pack_a_pairs_major(m, k, lhs) } };
        let out_ptr = SendPtr(out);
        let bpack = &bpack;
        let apack = &apack;
        let run_tile = |t: usize, scratch: &mut Vec<u32>| {
            let i0 = t * MR;
            let rows = MR.min(m - i0);
            let a = if row_contiguous {
                // The next tile's rows, into L2 while this tile computes (a tile's products
                // take thousands of cycles; its rows come from L3 or memory).
                for r in i0 + MR..(i0 + 2 * MR).min(m) {
                    unsafe { prefetch_row(lhs.row(r), k, lhs.cs) };
                }
                scratch.resize(rows * kp, 0);
                for r in 0..rows {
                    unsafe { convert_row(lhs.row(i0 + r), k, scratch.as_mut_ptr().add(r * kp)) };
                }
                APairs { base: scratch.as_ptr(), rs: kp, ps: 1 }
            } else {
                APairs { base: unsafe { apack.as_ptr().add(i0) }, rs: 1, ps: m }
            };
            for j in 0..panels {
                let cols = NR.min(n - j * NR);
                let c = unsafe { out_ptr.get().add(i0 * n + j * NR) };
                let b = unsafe { bpack.as_ptr().add(j * kp * NR) };
                unsafe { kernel_dispatch(rows, kp, a, b, c, n, cols, false) };
            }
            if epilogue.is_some() {
                // SAFETY: the tile's rows, which this closure alone writes.
                let tile =
                    unsafe { core::slice::from_raw_parts_mut(out_ptr.get().add(i0 * n), rows * n) };
                tile.chunks_exact_mut(n).for_each(|row| epilogue.apply_row(row, 0));
            }
        };
        let flops = m * n * k;
        #[cfg(feature = "rayon")]
        if flops >= 1 << 21 && tiles > 1 {
            use rayon::prelude::*;
            (0..tiles)
                .into_par_iter()
                .with_min_len(4)
                .for_each_init(Vec::new, |s, t| run_tile(t, s));
            return;
        }
        let _ = flops;
        let mut scratch = Vec::new();
        for t in 0..tiles {
            run_tile(t, &mut scratch);
        }
    }

    /// Row of k floats -> kp pairs.
    #[target_feature(enable = "avx512f,avx512bw,avx512bf16")]
    pub(crate) unsafe fn convert_row(src: *const f32, k: usize, dst: *mut u32) {
        let mut j = 0;
        unsafe {
            while j + 32 <= k {
                let lo = _mm512_loadu_ps(src.add(j));
                let hi = _mm512_loadu_ps(src.add(j + 16));
                let v: __m512i = core::mem::transmute(_mm512_cvtne2ps_pbh(hi, lo));
                _mm512_storeu_si512(dst.add(j / 2) as *mut _, v);
                j += 32;
            }
            while j < k {
                let x1 = if j + 1 < k { *src.add(j + 1) } else { 0.0 };
                *dst.add(j / 2) = pair_bits(*src.add(j), x1);
                j += 2;
            }
        }
    }

    /// 16-bit lane order that turns (x_0 .. x_15, y_0 .. y_15) into pairs (x_0, y_0, x_1, ..).
    #[repr(C, align(64))]
    pub(crate) struct LaneOrder(pub(crate) [u16; 32]);

    pub(crate) static PAIR_ORDER: LaneOrder = {
        let mut o = [0u16; 32];
        let mut r = 0;
        while r < 16 {
            o[2 * r] = r as u16;
            o[2 * r + 1] = 16 + r as u16;
            r += 1;
        }
        LaneOrder(o)
    };

    /// Interleaves rows r0 and r1 (r1 may be null for zero) of 16 floats into 16 pairs at dst.
    #[target_feature(enable = "avx512f,avx512bw,avx512bf16")]
    #[inline]
    pub(crate) unsafe fn interleave16(r0: *const f32, r1: *const f32, dst: *mut u32) {
        unsafe {
            // Both rows in one conversion (r0 in the low 16 lanes, r1 or zero in the high),
            // then one permute into pairs (r0[c], r1[c]).
            let y = if r1.is_null() { _mm512_setzero_ps() } else { _mm512_loadu_ps(r1) };
            let xy: __m512i = core::mem::transmute(_mm512_cvtne2ps_pbh(y, _mm512_loadu_ps(r0)));
            let order = _mm512_loadu_si512(PAIR_ORDER.0.as_ptr() as *const _);
            _mm512_storeu_si512(dst as *mut _, _mm512_permutexvar_epi16(order, xy));
        }
    }

    /// Rows r0 and r0 + 1 (zero at or past `k_end`) of the right operand as one pair row of
    /// every panel: column c at `dst + (c / 32) * panel_stride + c % 32`, panel_stride = kp * 32.
    pub(crate) unsafe fn pack_b_pair(
        n: usize,
        r0: usize,
        k_end: usize,
        kp: usize,
        rhs: MatRef,
        dst: *mut u32,
    ) {
        let has1 = r0 + 1 < k_end;
        let mut j = 0;
        if rhs.cs == 1 {
            while j + 16 <= n {
                let s0 = unsafe { rhs.row(r0).add(j) };
                let s1 = if has1 { unsafe { s0.offset(rhs.rs) } } else { core::ptr::null() };
                let d = unsafe { dst.add((j / NR) * kp * NR + j % NR) };
                unsafe { interleave16(s0, s1, d) };
                j += 16;
            }
        }
        while j < n {
            let x0 = unsafe { rhs.at(r0, j) };
            let x1 = if has1 { unsafe { rhs.at(r0 + 1, j) } } else { 0.0 };
            unsafe { *dst.add((j / NR) * kp * NR + j % NR) = pair_bits(x0, x1) };
            j += 1;
        }
    }

    /// The right operand into panels [panel][p][32].
    unsafe fn pack_b(k: usize, n: usize, rhs: MatRef, out: &mut [u32]) {
        let kp = k.div_ceil(2);
        let base = SendPtr(out.as_mut_ptr());
        let pack = |p: usize| unsafe { pack_b_pair(n, 2 * p, k, kp, rhs, base.get().add(p * NR)) };
        #[cfg(feature = "rayon")]
        if k * n >= 1 << 16 {
            use rayon::prelude::*;
            (0..kp).into_par_iter().with_min_len(64).for_each(pack);
            return;
        }
        (0..kp).for_each(pack);
    }

    /// Rows r0 and r0 + 1 (zero at or past `k_end`) of a left operand read as pairs of columns:
    /// pair (lhs(i, r0), lhs(i, r0 + 1)) at `dst + i` for every row i.
    unsafe fn pack_a_pair(m: usize, r0: usize, k_end: usize, lhs: MatRef, dst: *mut u32) {
        let has1 = r0 + 1 < k_end;
        let mut i = 0;
        if lhs.rs == 1 {
            while i + 16 <= m {
                let s0 = unsafe { lhs.at_ptr(0, r0).add(i) };
                let s1 = if has1 { unsafe { s0.offset(lhs.cs) } } else { core::ptr::null() };
                unsafe { interleave16(s0, s1, dst.add(i)) };
                i += 16;
            }
        }
        while i < m {
            let x0 = unsafe { lhs.at(i, r0) };
            let x1 = if has1 { unsafe { lhs.at(i, r0 + 1) } } else { 0.0 };
            unsafe { *dst.add(i) = pair_bits(x0, x1) };
            i += 1;
        }
    }

    /// A left operand that is not row-contiguous, as pairs [p][m] (the kernel reads rs 1, ps m).
    unsafe fn pack_a_pairs_major(m: usize, k: usize, lhs: MatRef) -> Vec<u32> {
        let kp = k.div_ceil(2);
        let mut out = vec![0u32; kp * m];
        let base = SendPtr(out.as_mut_ptr());
        let pack_pair = |p: usize| unsafe { pack_a_pair(m, 2 * p, k, lhs, base.get().add(p * m)) };
        #[cfg(feature = "rayon")]
        if k * m >= 1 << 16 {
            use rayon::prelude::*;
            (0..kp).into_par_iter().with_min_len(64).for_each(pack_pair);
            return out;
        }
        (0..kp).for_each(pack_pair);
        out
    }

    #[allow(clippy::too_many_arguments)]
    unsafe fn kernel_dispatch(
        rows: usize,
        kp: usize,
        a: APairs,
        b: *const u32,
        c: *mut f32,
        ldc: usize,
        cols: usize,
        accumulate: bool,
    ) {
        unsafe {
            match rows {
                12 => kernel::<12>(kp, a, b, c, ldc, cols, accumulate),
                11 => kernel::<11>(kp, a, b, c, ldc, cols, accumulate),
                10 => kernel::<10>(kp, a, b, c, ldc, cols, accumulate),
                9 => kernel::<9>(kp, a, b, c, ldc, cols, accumulate),
                8 => kernel::<8>(kp, a, b, c, ldc, cols, accumulate),
                7 => kernel::<7>(kp, a, b, c, ldc, cols, accumulate),
                6 => kernel::<6>(kp, a, b, c, ldc, cols, accumulate),
                5 => kernel::<5>(kp, a, b, c, ldc, cols, accumulate),
                4 => kernel::<4>(kp, a, b, c, ldc, cols, accumulate),
                3 => kernel::<3>(kp, a, b, c, ldc, cols, accumulate),
                2 => kernel::<2>(kp, a, b, c, ldc, cols, accumulate),
                1 => kernel::<1>(kp, a, b, c, ldc, cols, accumulate),
                _ => unreachable!("tile rows {rows}"),
            }
        }
    }

    /// C[R x cols] (+)= sum over kp pairs of A pairs (broadcast) times B's 32-column panel.
    #[target_feature(enable = "avx512f,avx512bw,avx512bf16")]
    #[allow(clippy::too_many_arguments)]
    unsafe fn kernel<const R: usize>(
        kp: usize,
        a: APairs,
        b: *const u32,
        c: *mut f32,
        ldc: usize,
        cols: usize,
        accumulate: bool,
    ) {
        let mut acc = [[_mm512_setzero_ps(); 2]; R];
        let m0: __mmask16 = if cols >= 16 { 0xFFFF } else { (1u16 << cols) - 1 };
        let m1: __mmask16 = if cols >= 32 {
            0xFFFF
        } else if cols > 16 {
            (1u16 << (cols - 16)) - 1
        } else {
            0
        };
        unsafe {
            if accumulate {
                for (r, acc_r) in acc.iter_mut().enumerate() {
                    let row = c.add(r * ldc);
                    acc_r[0] = _mm512_maskz_loadu_ps(m0, row);
                    if m1 != 0 {
                        acc_r[1] = _mm512_maskz_loadu_ps(m1, row.add(16));
                    }
                }
            }
            for p in 0..kp {
                let b0: __m512bh =
                    core::mem::transmute(_mm512_loadu_si512(b.add(p * NR) as *const _));
                let b1: __m512bh =
                    core::mem::transmute(_mm512_loadu_si512(b.add(p * NR + 16) as *const _));
                let ap = a.base.add(p * a.ps);
                for (r, acc_r) in acc.iter_mut().enumerate() {
                    let av: __m512bh =
                        core::mem::transmute(_mm512_set1_epi32(*ap.add(r * a.rs) as i32));
                    acc_r[0] = _mm512_dpbf16_ps(acc_r[0], av, b0);
                    acc_r[1] = _mm512_dpbf16_ps(acc_r[1], av, b1);
                }
            }
            for (r, acc_r) in acc.iter().enumerate() {
                let row = c.add(r * ldc);
                _mm512_mask_storeu_ps(row, m0, acc_r[0]);
                if m1 != 0 {
                    _mm512_mask_storeu_ps(row.add(16), m1, acc_r[1]);
                }
            }
        }
    }
}
