//! The AVX512-FP16 kernel of [`crate::f16dot`]: the same value as its emulation, to the bit.
//!
//! A tile is 12 rows x 32 columns. Per k, one 64-byte row of the right operand's panel is
//! loaded and each of the 12 rows' binary16 is broadcast from memory by its `vfmadd231ph`
//! (inline assembly: Rust has no stable binary16 intrinsics; the conversions are AVX-512F's).
//! After each run of [`RUN`] k the 12 binary16 accumulators are widened and added to 24 f32
//! ones (more than the registers hold with them: 12 chains of multiply-adds are what hides the
//! instruction's latency, and the f32 sums are touched once a run). The left operand is packed per tile in one of two layouts: rows of [`KB`] k (a
//! row-major operand, the forward and input-gradient products) or k-major, the tile's 12 values
//! of one k side by side (a k-major operand, the weight gradient's activations).

use crate::bf16dot::x86::SendPtr;
use crate::f16dot::{RUN, parts, pow2, scale_exp};
use crate::{Epilogue, MatRef};
use alloc::vec;
use alloc::vec::Vec;
use core::arch::asm;
use core::arch::x86_64::*;

const MR: usize = 12;
const NR: usize = 32;
/// k per row block of the row-major tile layout (its row stride, a multiple of [`RUN`]).
const KB: usize = 256;

/// How a packed tile of the left operand is laid out.
#[derive(Clone, Copy, PartialEq)]
enum Layout {
    /// [k / KB][MR][KB]: row i's k-th value at `((k / KB) MR + i) KB + k % KB`.
    RowBlocks,
    /// [k][MR]: row i's k-th value at `k MR + i`.
    KMajor,
}

/// A run's multiply-adds for one layout: `len` (>= 1) k, `pa` at row 0's first k, `pb` at the
/// panel's; row i's binary16 at `pa + i * ROW` bytes, the next k at `pa + STEP`.
macro_rules! run_fn {
    ($(#[$doc:meta])* $name:ident, row $row:literal, step $step:literal) => {
        $(#[$doc])*
        #[target_feature(enable = "avx512f,avx512bw,avx512vl,avx512fp16")]
        #[inline]
        unsafe fn $name(pa: *const u16, pb: *const u16, len: usize, c: &mut [__m512i; MR]) {
            unsafe {
                asm!(
                    "2:",
                    "vmovdqu16 {b}, [{pb}]",
                    "vfmadd231ph {c0}, {b}, word ptr [{pa}]{{1to32}}",
                    concat!("vfmadd231ph {c1}, {b}, word ptr [{pa} + ", $row, "]{{1to32}}"),
                    concat!("vfmadd231ph {c2}, {b}, word ptr [{pa} + 2 * ", $row, "]{{1to32}}"),
                    concat!("vfmadd231ph {c3}, {b}, word ptr [{pa} + 3 * ", $row, "]{{1to32}}"),
                    concat!("vfmadd231ph {c4}, {b}, word ptr [{pa} + 4 * ", $row, "]{{1to32}}"),
                    concat!("vfmadd231ph {c5}, {b}, word ptr [{pa} + 5 * ", $row, "]{{1to32}}"),
                    concat!("vfmadd231ph {c6}, {b}, word ptr [{pa} + 6 * ", $row, "]{{1to32}}"),
                    concat!("vfmadd231ph {c7}, {b}, word ptr [{pa} + 7 * ", $row, "]{{1to32}}"),
                    concat!("vfmadd231ph {c8}, {b}, word ptr [{pa} + 8 * ", $row, "]{{1to32}}"),
                    concat!("vfmadd231ph {c9}, {b}, word ptr [{pa} + 9 * ", $row, "]{{1to32}}"),
                    concat!("vfmadd231ph {c10}, {b}, word ptr [{pa} + 10 * ", $row, "]{{1to32}}"),
                    concat!("vfmadd231ph {c11}, {b}, word ptr [{pa} + 11 * ", $row, "]{{1to32}}"),
                    concat!("add {pa}, ", $step),
                    "add {pb}, 64",
                    "dec {n}",
                    "jnz 2b",
                    pa = inout(reg) pa => _,
                    pb = inout(reg) pb => _,
                    n = inout(reg) len => _,
                    b = out(zmm_reg) _,
                    c0 = inout(zmm_reg) c[0],
                    c1 = inout(zmm_reg) c[1],
                    c2 = inout(zmm_reg) c[2],
                    c3 = inout(zmm_reg) c[3],
                    c4 = inout(zmm_reg) c[4],
                    c5 = inout(zmm_reg) c[5],
                    c6 = inout(zmm_reg) c[6],
                    c7 = inout(zmm_reg) c[7],
                    c8 = inout(zmm_reg) c[8],
                    c9 = inout(zmm_reg) c[9],
                    c10 = inout(zmm_reg) c[10],
                    c11 = inout(zmm_reg) c[11],
                    options(nostack, readonly),
                );
            }
        }
    };
}

// The assembly names 12 accumulators.
const _: () = assert!(MR == 12);

run_fn!(
    /// The RowBlocks layout: rows [`KB`] binary16 (512 bytes) apart.
    run_row_blocks, row "512", step "2"
);
run_fn!(
    /// The KMajor layout: a k's 12 rows side by side.
    run_k_major, row "2", step "24"
);

/// One tile over k: the packed left tile `a`, the panel `b` ([k][32]); writes
/// `(sum * ia[i]) * ib[j]`, then the epilogue (`bias`: the panel's first column's bias), for the
/// first `rows` rows and `cols` columns at `c` (row stride `ldc`).
#[target_feature(enable = "avx512f,avx512bw,avx512vl,avx512fp16")]
#[allow(clippy::too_many_arguments)]
unsafe fn tile(
    layout: Layout,
    a: *const u16,
    b: *const u16,
    k: usize,
    ia: &[f32; MR],
    ib: *const f32,
    c: *mut f32,
    ldc: usize,
    rows: usize,
    cols: usize,
    bias: Option<*const f32>,
    relu: bool,
) {
    unsafe {
        let mut h = [_mm512_setzero_si512(); MR];
        let mut s = [_mm512_setzero_ps(); 2 * MR];
        let mut k0 = 0;
        while k0 < k {
            let len = RUN.min(k - k0);
            let pb = b.add(k0 * NR);
            match layout {
                Layout::RowBlocks => {
                    let pa = a.add((k0 / KB) * MR * KB + k0 % KB);
                    run_row_blocks(pa, pb, len, &mut h);
                }
                Layout::KMajor => run_k_major(a.add(k0 * MR), pb, len, &mut h),
            }
            for i in 0..MR {
                let lo = _mm512_cvtph_ps(_mm512_castsi512_si256(h[i]));
                let hi = _mm512_cvtph_ps(_mm512_extracti64x4_epi64::<1>(h[i]));
                s[2 * i] = _mm512_add_ps(s[2 * i], lo);
                s[2 * i + 1] = _mm512_add_ps(s[2 * i + 1], hi);
                h[i] = _mm512_setzero_si512();
            }
            k0 += RUN;
        }
        let m0: __mmask16 = if cols >= 16 { 0xffff } else { (1u32 << cols) as u16 - 1 };
        let m1: __mmask16 =
            if cols >= 32 { 0xffff } else { ((1u32 << cols.saturating_sub(16)) - 1) as u16 };
        let ib0 = _mm512_maskz_loadu_ps(m0, ib);
        let ib1 = _mm512_maskz_loadu_ps(m1, ib.add(16));
        let (b0, b1) = match bias {
            Some(b) => (_mm512_maskz_loadu_ps(m0, b), _mm512_maskz_loadu_ps(m1, b.add(16))),
            None => (_mm512_setzero_ps(), _mm512_setzero_ps()),
        };
        // The epilogue's operations per element ([`Epilogue::apply_row`]): one f32 addition
        // of the bias, then burn-flex's ReLU (x where x > 0 or x is NaN, else +0).
        let finish = |x: __m512, b: __m512| {
            let x = if bias.is_some() { _mm512_add_ps(x, b) } else { x };
            if relu {
                let keep = _mm512_cmp_ps_mask::<_CMP_GT_OQ>(x, _mm512_setzero_ps())
                    | _mm512_cmp_ps_mask::<_CMP_UNORD_Q>(x, x);
                _mm512_maskz_mov_ps(keep, x)
            } else {
                x
            }
        };
        for (i, &scale) in ia.iter().enumerate().take(rows) {
            let r = _mm512_set1_ps(scale);
            let dst = c.add(i * ldc);
            let v0 = finish(_mm512_mul_ps(_mm512_mul_ps(s[2 * i], r), ib0), b0);
            let v1 = finish(_mm512_mul_ps(_mm512_mul_ps(s[2 * i + 1], r), ib1), b1);
            _mm512_mask_storeu_ps(dst, m0, v0);
            _mm512_mask_storeu_ps(dst.add(16), m1, v1);
        }
    }
}

/// 16 floats from `src` (the first `len`, the rest 0) times `scale`, rounded to binary16 at `dst`.
#[target_feature(enable = "avx512f,avx512bw,avx512vl,avx512fp16")]
#[inline]
unsafe fn convert16(src: *const f32, len: usize, scale: __m512, dst: *mut u16) {
    unsafe {
        let mask: __mmask16 = if len >= 16 { 0xffff } else { ((1u32 << len) - 1) as u16 };
        let x = _mm512_mul_ps(_mm512_maskz_loadu_ps(mask, src), scale);
        let h = _mm512_cvtps_ph::<{ _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC }>(x);
        _mm256_storeu_si256(dst as *mut __m256i, h);
    }
}

/// One f32 rounded to binary16 bits (the scalar paths for strided operands).
#[target_feature(enable = "avx512f,avx512bw,avx512vl,avx512fp16")]
#[inline]
unsafe fn convert1(x: f32) -> u16 {
    let h = _mm_cvtps_ph::<_MM_FROUND_TO_NEAREST_INT>(_mm_set_ss(x));
    _mm_extract_epi16::<0>(h) as u16
}

/// The largest magnitude of `len` floats from `src` at stride `stride`.
#[target_feature(enable = "avx512f,avx512bw,avx512vl,avx512fp16")]
unsafe fn amax(src: *const f32, len: usize, stride: isize) -> f32 {
    unsafe {
        if stride == 1 {
            let mut v = _mm512_setzero_ps();
            let mut j = 0;
            while j < len {
                let mask: __mmask16 =
                    if len - j >= 16 { 0xffff } else { ((1u32 << (len - j)) - 1) as u16 };
                v = _mm512_max_ps(_mm512_abs_ps(_mm512_maskz_loadu_ps(mask, src.add(j))), v);
                j += 16;
            }
            return _mm512_reduce_max_ps(v);
        }
        (0..len).map(|j| (*src.offset(j as isize * stride)).abs()).fold(0f32, f32::max)
    }
}

/// One contiguous row of `len` <= [`KB`] floats scaled by its own power of two and rounded to
/// binary16 at `dst`, read once (into registers, then scaled); returns the inverse scale.
#[target_feature(enable = "avx512f,avx512bw,avx512vl,avx512fp16")]
unsafe fn row_to_f16(src: *const f32, len: usize, dst: *mut u16) -> f32 {
    unsafe {
        let mut v = [_mm512_setzero_ps(); KB / 16];
        let mut mx = _mm512_setzero_ps();
        let chunks = len.div_ceil(16);
        for (c, x) in v.iter_mut().enumerate().take(chunks) {
            let left = len - 16 * c;
            let mask: __mmask16 = if left >= 16 { 0xffff } else { ((1u32 << left) - 1) as u16 };
            *x = _mm512_maskz_loadu_ps(mask, src.add(16 * c));
            mx = _mm512_max_ps(_mm512_abs_ps(*x), mx);
        }
        let e = scale_exp(_mm512_reduce_max_ps(mx));
        let sv = _mm512_set1_ps(pow2(e));
        for (c, x) in v.iter().enumerate().take(chunks) {
            let h = _mm512_cvtps_ph::<_MM_FROUND_TO_NEAREST_INT>(_mm512_mul_ps(*x, sv));
            _mm256_storeu_si256(dst.add(16 * c) as *mut __m256i, h);
        }
        pow2(-e)
    }
}

/// Every tile of a left operand stored transposed (`lhs.rs` 1: the activations of a weight
/// gradient) over k in `k0..k1`, in one pass over its stored rows: tiles [m / MR][k1 - k0][MR]
/// (zero-padded), the rows' inverse scales (padded to whole tiles).
#[target_feature(enable = "avx512f,avx512bw,avx512vl,avx512fp16")]
unsafe fn pack_a_k_major_all(lhs: MatRef, m: usize, k0: usize, k1: usize) -> (Vec<u16>, Vec<f32>) {
    let kl = k1 - k0;
    let tiles = m.div_ceil(MR);
    let exps = unsafe { line_exps(lhs.ptr, lhs.cs, m, k0, k1) };
    let mut scale = vec![0f32; tiles * MR + 16];
    let mut ia = vec![0f32; tiles * MR];
    for (i, &e) in exps.iter().enumerate() {
        scale[i] = pow2(e);
        ia[i] = pow2(-e);
    }
    let mut dst = vec![0u16; tiles * kl * MR];
    let d = dst.as_mut_ptr();
    unsafe {
        for kk in 0..kl {
            let line = lhs.at_ptr(0, k0 + kk);
            for t in 0..tiles {
                let rows = MR.min(m - t * MR);
                let mask: __mmask16 = ((1u32 << rows) - 1) as u16;
                let x = _mm512_maskz_loadu_ps(mask, line.add(t * MR));
                let sv = _mm512_loadu_ps(scale.as_ptr().add(t * MR));
                let h = _mm512_cvtps_ph::<_MM_FROUND_TO_NEAREST_INT>(_mm512_mul_ps(x, sv));
                _mm256_mask_storeu_epi16(d.add((t * kl + kk) * MR) as *mut i16, 0x0fff, h);
            }
        }
    }
    (dst, ia)
}

/// Rows `i0..i0 + rows` of `lhs` over k in `k0..k1`, packed as a tile of `layout` into `dst`
/// (zero-padded to MR rows), with the rows' inverse scales into `ia`.
#[target_feature(enable = "avx512f,avx512bw,avx512vl,avx512fp16")]
#[allow(clippy::too_many_arguments)]
unsafe fn pack_a(
    layout: Layout,
    lhs: MatRef,
    i0: usize,
    rows: usize,
    k0: usize,
    k1: usize,
    dst: &mut Vec<u16>,
    ia: &mut [f32; MR],
    exps: Option<&[i32]>,
) {
    let kl = k1 - k0;
    let len = match layout {
        Layout::RowBlocks => kl.div_ceil(KB) * MR * KB,
        Layout::KMajor => kl * MR,
    };
    dst.clear();
    dst.resize(len, 0);
    let mut scale = [0f32; MR];
    let fused = layout == Layout::RowBlocks && lhs.cs == 1 && kl <= KB && exps.is_none();
    for i in 0..MR {
        let e = match exps {
            _ if fused => 0,
            _ if i >= rows => 0,
            Some(e) => e[i0 + i],
            None => scale_exp(unsafe { amax(lhs.at_ptr(i0 + i, k0), kl, lhs.cs) }),
        };
        scale[i] = pow2(e);
        ia[i] = pow2(-e);
    }
    let d = dst.as_mut_ptr();
    unsafe {
        match layout {
            Layout::RowBlocks if lhs.cs == 1 && kl <= KB && exps.is_none() => {
                for (i, inv) in ia.iter_mut().enumerate().take(rows) {
                    *inv = row_to_f16(lhs.at_ptr(i0 + i, k0), kl, d.add(i * KB));
                }
            }
            Layout::RowBlocks => {
                for (i, &sc) in scale.iter().enumerate().take(rows) {
                    let src = lhs.at_ptr(i0 + i, k0);
                    let mut j = 0;
                    while j < kl {
                        let at = d.add(((j / KB) * MR + i) * KB + j % KB);
                        if lhs.cs == 1 {
                            convert16(src.add(j), (kl - j).min(16), _mm512_set1_ps(sc), at);
                            j += 16;
                        } else {
                            *at = convert1(*src.offset(j as isize * lhs.cs) * sc);
                            j += 1;
                        }
                    }
                }
            }
            Layout::KMajor => {
                if lhs.rs == 1 {
                    // The tile's rows of one k are contiguous: one masked load and store.
                    let mask: __mmask16 = ((1u32 << rows) - 1) as u16;
                    let mut sc16 = [0f32; 16];
                    sc16[..MR].copy_from_slice(&scale);
                    let sv = _mm512_loadu_ps(sc16.as_ptr());
                    for j in 0..kl {
                        let x = _mm512_maskz_loadu_ps(mask, lhs.at_ptr(i0, k0 + j));
                        let h = _mm512_cvtps_ph::<_MM_FROUND_TO_NEAREST_INT>(_mm512_mul_ps(x, sv));
                        _mm256_mask_storeu_epi16(d.add(j * MR) as *mut i16, 0x0fff, h);
                    }
                } else {
                    for j in 0..kl {
                        for (i, &sc) in scale.iter().enumerate().take(rows) {
                            *d.add(j * MR + i) = convert1(lhs.at(i0 + i, k0 + j) * sc);
                        }
                    }
                }
            }
        }
    }
}

/// The scale exponents of `n` contiguous lanes over the lines `k0..k1` (line kk's lanes at
/// `base + kk stride`): a row-major right operand's columns, or the rows of a left operand
/// stored transposed.
#[target_feature(enable = "avx512f,avx512bw,avx512vl,avx512fp16")]
unsafe fn line_exps(base: *const f32, stride: isize, n: usize, k0: usize, k1: usize) -> Vec<i32> {
    let mut mx = vec![0f32; n.next_multiple_of(16)];
    unsafe {
        for kk in k0..k1 {
            let line = base.offset(kk as isize * stride);
            let mut j = 0;
            while j < n {
                let mask: __mmask16 =
                    if n - j >= 16 { 0xffff } else { ((1u32 << (n - j)) - 1) as u16 };
                let v = _mm512_abs_ps(_mm512_maskz_loadu_ps(mask, line.add(j)));
                let cur = _mm512_loadu_ps(mx.as_ptr().add(j));
                // The maximum of a NaN lane is the other operand: a NaN element leaves its
                // line's scale to the others, and its products NaN.
                _mm512_storeu_ps(mx.as_mut_ptr().add(j), _mm512_max_ps(v, cur));
                j += 16;
            }
        }
    }
    mx[..n].iter().map(|&a| scale_exp(a)).collect()
}

/// Columns of `rhs` over k in `k0..k1` into panels [n / 32][k1 - k0][32] (zero-padded), the
/// columns' inverse scales into `ib` (padded to whole panels).
#[target_feature(enable = "avx512f,avx512bw,avx512vl,avx512fp16")]
unsafe fn pack_b(
    rhs: MatRef,
    n: usize,
    k0: usize,
    k1: usize,
    dst: &mut Vec<u16>,
    ib: &mut Vec<f32>,
) {
    let kl = k1 - k0;
    let panels = n.div_ceil(NR);
    dst.clear();
    dst.resize(panels * kl * NR, 0);
    ib.clear();
    ib.resize(panels * NR, 0.0);
    let mut scale = vec![0f32; panels * NR];
    unsafe {
        if rhs.cs == 1 {
            for (j, e) in line_exps(rhs.ptr, rhs.rs, n, k0, k1).into_iter().enumerate() {
                scale[j] = pow2(e);
                ib[j] = pow2(-e);
            }
            let d = dst.as_mut_ptr();
            for kk in 0..kl {
                let row = rhs.row(k0 + kk);
                let mut j = 0;
                while j < n {
                    let at = d.add((j / NR) * kl * NR + kk * NR + j % NR);
                    let sv = _mm512_loadu_ps(scale.as_ptr().add(j));
                    convert16(row.add(j), (n - j).min(16), sv, at);
                    j += 16;
                }
            }
        } else if rhs.rs == 1 {
            // Stored transposed (the weight of an input gradient, small): a row-major copy of
            // the k range, then the contiguous path; the same values and scales.
            let mut copy = vec![0f32; kl * n];
            for j in 0..n {
                let col = rhs.at_ptr(k0, j);
                for (kk, x) in (0..kl).zip(copy.iter_mut().skip(j).step_by(n)) {
                    *x = *col.add(kk);
                }
            }
            let view = MatRef { ptr: copy.as_ptr(), rs: n as isize, cs: 1 };
            pack_b(view, n, 0, kl, dst, ib);
        } else {
            for j in 0..n {
                let e = scale_exp(amax(rhs.at_ptr(k0, j), kl, rhs.rs));
                scale[j] = pow2(e);
                ib[j] = pow2(-e);
            }
            let d = dst.as_mut_ptr();
            for kk in 0..kl {
                for (j, &sc) in scale.iter().enumerate().take(n) {
                    *d.add((j / NR) * kl * NR + kk * NR + j % NR) =
                        convert1(rhs.at(k0 + kk, j) * sc);
                }
            }
        }
    }
}

/// out = epilogue(lhs rhs), the value of [`crate::f16dot`]'s docs.
///
/// # Safety
/// As [`crate::f16dot::matmul_f16`], on a CPU with AVX512-FP16.
pub(crate) unsafe fn matmul(
    m: usize,
    n: usize,
    k: usize,
    lhs: MatRef,
    rhs: MatRef,
    out: *mut f32,
    epilogue: Epilogue,
) {
    let (count, per) = parts(m, n, k);
    if count == 1 {
        unsafe { by_rows(m, n, k, lhs, rhs, out, epilogue) };
    } else {
        unsafe { split_k(m, n, k, count, per, lhs, rhs, out) };
        unsafe { epilogue.apply_rows(m, n, out) };
    }
}

/// One part (the whole k): tiles of rows in parallel, the epilogue applied in each tile's store.
unsafe fn by_rows(
    m: usize,
    n: usize,
    k: usize,
    lhs: MatRef,
    rhs: MatRef,
    out: *mut f32,
    epilogue: Epilogue,
) {
    let (mut bpack, mut ib) = (Vec::new(), Vec::new());
    unsafe { pack_b(rhs, n, 0, k, &mut bpack, &mut ib) };
    let tiles = m.div_ceil(MR);
    let panels = n.div_ceil(NR);
    let out = SendPtr(out);
    let (bpack, ib) = (&bpack, &ib);
    let run_tile = |t: usize, scratch: &mut Vec<u16>| {
        let i0 = t * MR;
        let rows = MR.min(m - i0);
        let mut ia = [0f32; MR];
        let layout = if lhs.cs == 1 || lhs.rs != 1 { Layout::RowBlocks } else { Layout::KMajor };
        unsafe { pack_a(layout, lhs, i0, rows, 0, k, scratch, &mut ia, None) };
        for j in 0..panels {
            let cols = NR.min(n - j * NR);
            unsafe {
                tile(
                    layout,
                    scratch.as_ptr(),
                    bpack.as_ptr().add(j * k * NR),
                    k,
                    &ia,
                    ib.as_ptr().add(j * NR),
                    out.get().add(i0 * n + j * NR),
                    n,
                    rows,
                    cols,
                    epilogue.bias.map(|b| b[j * NR..].as_ptr()),
                    epilogue.relu,
                )
            };
        }
    };
    #[cfg(feature = "rayon")]
    if m * n * k >= 1 << 21 && tiles > 1 {
        use rayon::prelude::*;
        (0..tiles).into_par_iter().with_min_len(4).for_each_init(Vec::new, |s, t| run_tile(t, s));
        return;
    }
    let mut scratch = Vec::new();
    for t in 0..tiles {
        run_tile(t, &mut scratch);
    }
}

/// The parts of k in parallel, each into its own m x n partial; then the partials added in
/// part order.
#[allow(clippy::too_many_arguments)]
unsafe fn split_k(
    m: usize,
    n: usize,
    k: usize,
    count: usize,
    per: usize,
    lhs: MatRef,
    rhs: MatRef,
    out: *mut f32,
) {
    let part = |p: usize| -> Vec<f32> {
        let (k0, k1) = (p * per, ((p + 1) * per).min(k));
        let mut c = vec![0f32; m * n];
        let (mut bpack, mut ib, mut apack) = (Vec::new(), Vec::new(), Vec::new());
        unsafe { pack_b(rhs, n, k0, k1, &mut bpack, &mut ib) };
        let layout = if lhs.rs == 1 && lhs.cs != 1 { Layout::KMajor } else { Layout::RowBlocks };
        // Stored transposed (the activations of a weight gradient), all tiles in one pass.
        let all = (layout == Layout::KMajor).then(|| unsafe { pack_a_k_major_all(lhs, m, k0, k1) });
        let mut ia = [0f32; MR];
        for t in 0..m.div_ceil(MR) {
            let i0 = t * MR;
            let rows = MR.min(m - i0);
            let a = match &all {
                Some((packed, inv)) => {
                    ia.copy_from_slice(&inv[i0..i0 + MR]);
                    unsafe { packed.as_ptr().add(t * (k1 - k0) * MR) }
                }
                None => {
                    unsafe { pack_a(layout, lhs, i0, rows, k0, k1, &mut apack, &mut ia, None) };
                    apack.as_ptr()
                }
            };
            for j in 0..n.div_ceil(NR) {
                unsafe {
                    tile(
                        layout,
                        a,
                        bpack.as_ptr().add(j * (k1 - k0) * NR),
                        k1 - k0,
                        &ia,
                        ib.as_ptr().add(j * NR),
                        c.as_mut_ptr().add(i0 * n + j * NR),
                        n,
                        rows,
                        NR.min(n - j * NR),
                        None,
                        false,
                    )
                };
            }
        }
        c
    };
    #[cfg(feature = "rayon")]
    let partials: Vec<Vec<f32>> = {
        use rayon::prelude::*;
        (0..count).into_par_iter().map(part).collect()
    };
    #[cfg(not(feature = "rayon"))]
    let partials: Vec<Vec<f32>> = (0..count).map(part).collect();
    // SAFETY: `out` holds m n floats, written here only.
    let dst = unsafe { core::slice::from_raw_parts_mut(out, m * n) };
    dst.copy_from_slice(&partials[0]);
    for p in &partials[1..] {
        for (d, s) in dst.iter_mut().zip(p) {
            *d += s;
        }
    }
}
