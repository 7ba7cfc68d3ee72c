//! bf16 dot products on Intel's AMX tiles.
//!
//! The same product as [`crate::bf16dot`] (operands rounded to bf16 with round to
//! nearest even, products summed in f32, f32 output) on the tile unit of Xeons from Sapphire
//! Rapids on: one `tdpbf16ps` multiplies a 16 x 32 bf16 tile by a 32 x 16 one into a 16 x 16
//! f32 tile, 8,192 multiply-adds, where an AVX-512 `vdpbf16ps` does 32. On such a Xeon the
//! `vdpbf16ps` kernel was measured slower than f32, so this path is what makes bf16 worth
//! having there.
//!
//! A block of 32 x 32 outputs lives in four accumulator tiles (tmm0..3) while two tiles of the
//! left operand (tmm4, tmm5: 32 rows x 32 k) and two of the right (tmm6, tmm7: 32 k x 32
//! columns) stream through. The operands are packed as in the AVX-512 kernel: the left one row
//! by row as bf16 pairs (two consecutive k of one row in one u32, zero past k), the right one in
//! panels of 32 columns, each k pair of a column one u32 ("VNNI" layout), which is exactly the
//! layout of a tile's right operand. The inner dimension is padded with zero pairs to a
//! multiple of 16 pairs (32 k); partial blocks of rows or columns are computed whole and only
//! their valid part is copied out.
//!
//! Linux gives a process the tile registers only on request (`arch_prctl(ARCH_REQ_XCOMP_PERM,
//! XFEATURE_XTILEDATA)`); [`amx_available`] asks once and answers false when the CPU lacks
//! AMX-TILE or AMX-BF16 or when the request fails. Whether a product takes the tiles where they
//! are available is the caller's, an argument of the product ([`crate::Precision::Bf16`]'s
//! `amx`), never a process-wide switch. Every task configures the tiles on its own thread and
//! releases them when it is done.

use crate::Epilogue;
use crate::bf16dot::MatRef;
use crate::bf16dot::pair_bits;
use crate::bf16dot::x86::{PAIR_ORDER, SendPtr, convert_row, pack_b_pair};
use alloc::vec;
use alloc::vec::Vec;
use core::arch::asm;
use core::arch::x86_64::*;

/// Output rows and columns of one block (2 x 2 tiles of 16 x 16).
const MB: usize = 32;
const NB: usize = 32;
/// k pairs of one tile step.
const KT: usize = 16;
/// Pairs per k block of the split-k path.
const KC_PAIRS: usize = 512;
/// Blocks of rows per parallel task (one tile configuration each).
const BLOCKS_PER_TASK: usize = 8;

/// Whether this process can run bf16 products on AMX tiles: the CPU has AMX-TILE and
/// AMX-BF16 and Linux granted the tile registers (asked once, on first use).
pub fn amx_available() -> bool {
    static AVAILABLE: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *AVAILABLE.get_or_init(detect)
}

fn detect() -> bool {
    if !crate::bf16dot::bf16_dot_native() || __cpuid(0).eax < 7 {
        return false;
    }
    let edx = __cpuid_count(7, 0).edx;
    let (amx_bf16, amx_tile) = ((edx >> 22) & 1 == 1, (edx >> 24) & 1 == 1);
    amx_bf16 && amx_tile && request_tile_permission()
}

/// `arch_prctl(ARCH_REQ_XCOMP_PERM, XFEATURE_XTILEDATA)`: true when Linux grants this process
/// the tile data registers (kernel 5.16 and later).
fn request_tile_permission() -> bool {
    const SYS_ARCH_PRCTL: i64 = 158;
    const ARCH_REQ_XCOMP_PERM: i64 = 0x1023;
    const XFEATURE_XTILEDATA: i64 = 18;
    let ret: i64;
    // SAFETY: the syscall reads its two integer arguments only; rcx and r11 are clobbered.
    unsafe {
        asm!(
            "syscall",
            inlateout("rax") SYS_ARCH_PRCTL => ret,
            in("rdi") ARCH_REQ_XCOMP_PERM,
            in("rsi") XFEATURE_XTILEDATA,
            lateout("rcx") _,
            lateout("r11") _,
            options(nostack),
        );
    }
    ret == 0
}

/// Palette 1, tiles 0..7 all 16 rows of 64 bytes.
#[repr(C, align(64))]
struct TileConfig([u8; 64]);

static TILE_CONFIG: TileConfig = {
    let mut c = [0u8; 64];
    c[0] = 1;
    let mut t = 0;
    while t < 8 {
        c[16 + 2 * t] = 64;
        c[48 + t] = 16;
        t += 1;
    }
    TileConfig(c)
};

/// Configures the tiles on this thread until the guard drops (`tilerelease`).
struct Tiles;

impl Tiles {
    fn configure() -> Tiles {
        // SAFETY: only called once `amx_available()` said the CPU and the OS allow tiles.
        unsafe { asm!("ldtilecfg [{}]", in(reg) TILE_CONFIG.0.as_ptr(), options(nostack)) };
        Tiles
    }
}

impl Drop for Tiles {
    fn drop(&mut self) {
        // SAFETY: the tiles were configured by `configure`.
        unsafe { asm!("tilerelease", options(nostack, nomem)) };
    }
}

/// C (32 x 32 f32 at `c`, row stride `ldc` bytes) = (or +=, with `accumulate`) the left block
/// (32 rows of pairs at `a`, row stride `lda` bytes) times the right panel (pair rows of 32
/// columns at `b`, 128 bytes each), over `steps` steps of 16 pairs.
///
/// # Safety
/// Tiles configured on this thread ([`Tiles`]); the operands and `c` cover what is read and
/// written.
#[inline]
unsafe fn block(
    a: *const u32,
    lda: usize,
    b: *const u32,
    steps: usize,
    c: *mut f32,
    ldc: usize,
    accumulate: bool,
) {
    let c1 = unsafe { c.add(16) };
    let c2 = unsafe { c.byte_add(16 * ldc) };
    let c3 = unsafe { c2.add(16) };
    unsafe {
        if accumulate {
            asm!(
                "tileloadd tmm0, [{c0} + {ldc}*1]",
                "tileloadd tmm1, [{c1} + {ldc}*1]",
                "tileloadd tmm2, [{c2} + {ldc}*1]",
                "tileloadd tmm3, [{c3} + {ldc}*1]",
                c0 = in(reg) c, c1 = in(reg) c1, c2 = in(reg) c2, c3 = in(reg) c3,
                ldc = in(reg) ldc, options(nostack, readonly),
            );
        } else {
            asm!(
                "tilezero tmm0",
                "tilezero tmm1",
                "tilezero tmm2",
                "tilezero tmm3",
                options(nostack, nomem),
            );
        }
        asm!(
            "2:",
            "tileloadd tmm4, [{a0} + {lda}*1]",
            "tileloadd tmm5, [{a1} + {lda}*1]",
            "tileloadd tmm6, [{b0} + {ldb}*1]",
            "tileloadd tmm7, [{b1} + {ldb}*1]",
            "tdpbf16ps tmm0, tmm4, tmm6",
            "tdpbf16ps tmm1, tmm4, tmm7",
            "tdpbf16ps tmm2, tmm5, tmm6",
            "tdpbf16ps tmm3, tmm5, tmm7",
            "add {a0}, 64",
            "add {a1}, 64",
            "add {b0}, 2048",
            "add {b1}, 2048",
            "dec {steps}",
            "jnz 2b",
            "tilestored [{c0} + {ldc}*1], tmm0",
            "tilestored [{c1} + {ldc}*1], tmm1",
            "tilestored [{c2} + {ldc}*1], tmm2",
            "tilestored [{c3} + {ldc}*1], tmm3",
            a0 = inout(reg) a => _,
            a1 = inout(reg) a.byte_add(16 * lda) => _,
            b0 = inout(reg) b => _,
            b1 = inout(reg) b.add(16) => _,
            lda = in(reg) lda,
            ldb = in(reg) NB * 4,
            steps = inout(reg) steps => _,
            c0 = in(reg) c, c1 = in(reg) c1, c2 = in(reg) c2, c3 = in(reg) c3,
            ldc = in(reg) ldc,
            options(nostack),
        );
    }
}

/// out (m x n, row-major) = epilogue(lhs (m x k) * rhs (k x n)) with bf16 operands on AMX
/// tiles. The epilogue (a bias per column, then a ReLU) is applied to each 32 x 32 block as it
/// leaves the tiles (fused linear layers), the same f32 operations as a separate pass.
///
/// # Safety
/// As [`crate::bf16dot::matmul_bf16dot`]; [`amx_available`] must be true; m, n, k > 0;
/// the epilogue's bias, if any, holds n values.
pub(crate) unsafe fn matmul(
    m: usize,
    n: usize,
    k: usize,
    lhs: MatRef,
    rhs: MatRef,
    out: *mut f32,
    epilogue: Epilogue,
) {
    #[cfg(feature = "rayon")]
    if k >= 2048 && m * n <= k * 16 {
        unsafe { split_k(m, n, k, lhs, rhs, out) };
        unsafe { epilogue.apply_rows(m, n, out) };
        return;
    }
    unsafe { by_rows(m, n, k, lhs, rhs, out, epilogue) }
}

/// Blocks of 32 rows in parallel, the whole k of a block in one tile loop.
unsafe fn by_rows(
    m: usize,
    n: usize,
    k: usize,
    lhs: MatRef,
    rhs: MatRef,
    out: *mut f32,
    epilogue: Epilogue,
) {
    let kp = k.div_ceil(2);
    let kpp = kp.next_multiple_of(KT);
    let panels = n.div_ceil(NB);
    let blocks = m.div_ceil(MB);
    let bpack = unsafe { pack_b(n, k, kpp, rhs) };
    let out_ptr = SendPtr(out);
    let bpack = &bpack;
    let run = |task: usize, scratch: &mut (Vec<u32>, Vec<f32>)| {
        let (apack, edge) = scratch;
        if apack.is_empty() {
            // Zero once: the pairs past k stay zero (0 x anything finite in the right panel).
            *apack = vec![0u32; MB * kpp];
            *edge = vec![0f32; MB * NB];
        }
        let _tiles = Tiles::configure();
        for blk in task * BLOCKS_PER_TASK..((task + 1) * BLOCKS_PER_TASK).min(blocks) {
            let i0 = blk * MB;
            let rows = MB.min(m - i0);
            // Rows past m keep an earlier block's pairs: their outputs are never copied out.
            unsafe { pack_a(lhs, i0, rows, 0, kp, k, apack.as_mut_ptr(), kpp) };
            for j in 0..panels {
                let cols = NB.min(n - j * NB);
                let b = unsafe { bpack.as_ptr().add(j * kpp * NB) };
                let c = unsafe { out_ptr.get().add(i0 * n + j * NB) };
                let a = apack.as_ptr();
                if rows == MB && cols == NB {
                    unsafe { block(a, kpp * 4, b, kpp / KT, c, n * 4, false) };
                    match epilogue {
                        Epilogue { bias: Some(bias), relu: false } => unsafe {
                            add_bias_block(c, n, bias.as_ptr().add(j * NB))
                        },
                        Epilogue { relu: true, .. } => {
                            for r in 0..MB {
                                // SAFETY: row r of the 32 x 32 block just stored.
                                let row =
                                    unsafe { core::slice::from_raw_parts_mut(c.add(r * n), NB) };
                                epilogue.apply_row(row, j * NB);
                            }
                        }
                        Epilogue { bias: None, relu: false } => {}
                    }
                } else {
                    unsafe { block(a, kpp * 4, b, kpp / KT, edge.as_mut_ptr(), NB * 4, false) };
                    for r in 0..rows {
                        let src = &edge[r * NB..r * NB + cols];
                        let dst = unsafe { core::slice::from_raw_parts_mut(c.add(r * n), cols) };
                        dst.copy_from_slice(src);
                        epilogue.apply_row(dst, j * NB);
                    }
                }
            }
        }
    };
    let tasks = blocks.div_ceil(BLOCKS_PER_TASK);
    #[cfg(feature = "rayon")]
    if m * n * k >= 1 << 21 && tasks > 1 {
        use rayon::prelude::*;
        (0..tasks).into_par_iter().for_each_init(|| (Vec::new(), Vec::new()), |s, t| run(t, s));
        return;
    }
    let mut scratch = (Vec::new(), Vec::new());
    for t in 0..tasks {
        run(t, &mut scratch);
    }
}

/// Adds 32 bias values (`bias`) to each of the 32 rows of a block just stored at `c` (row
/// stride `ldc` floats), while the block is still in L1.
#[target_feature(enable = "avx512f")]
#[inline]
unsafe fn add_bias_block(c: *mut f32, ldc: usize, bias: *const f32) {
    unsafe {
        let b0 = _mm512_loadu_ps(bias);
        let b1 = _mm512_loadu_ps(bias.add(16));
        for r in 0..MB {
            let row = c.add(r * ldc);
            _mm512_storeu_ps(row, _mm512_add_ps(_mm512_loadu_ps(row), b0));
            _mm512_storeu_ps(row.add(16), _mm512_add_ps(_mm512_loadu_ps(row.add(16)), b1));
        }
    }
}

/// Each part of k (`split_k::bf16_parts`, which depends on k alone) is summed into
/// its own padded partial, a block of k pairs at a time (both operands packed per block), the
/// parts in parallel; then the partials are added in part order.
#[cfg(feature = "rayon")]
unsafe fn split_k(m: usize, n: usize, k: usize, lhs: MatRef, rhs: MatRef, out: *mut f32) {
    use rayon::prelude::*;
    let pairs = k.div_ceil(2);
    let (parts, per) = crate::split_k::bf16_parts(pairs, KT);
    let (m_pad, n_pad) = (m.next_multiple_of(MB), n.next_multiple_of(NB));
    let panels = n_pad / NB;
    let partials: Vec<Vec<f32>> = (0..parts)
        .into_par_iter()
        .map(|t| {
            let (p0, p1) = ((t * per).min(pairs), ((t + 1) * per).min(pairs));
            let mut c = vec![0f32; m_pad * n_pad];
            if p0 == p1 {
                return c;
            }
            let mut apack = vec![0u32; m_pad * KC_PAIRS];
            let mut bpack = vec![0u32; panels * KC_PAIRS * NB];
            let _tiles = Tiles::configure();
            let mut q0 = p0;
            while q0 < p1 {
                let q1 = (q0 + KC_PAIRS).min(p1);
                let kpb = q1 - q0;
                if kpb < KC_PAIRS {
                    // The pairs past this block's end must be zero in both operands.
                    apack.fill(0);
                    bpack.fill(0);
                }
                unsafe { pack_a(lhs, 0, m, q0, q1, k, apack.as_mut_ptr(), KC_PAIRS) };
                let bp = SendPtr(bpack.as_mut_ptr());
                for q in 0..kpb {
                    unsafe { pack_b_pair(n, 2 * (q0 + q), k, KC_PAIRS, rhs, bp.get().add(q * NB)) };
                }
                let steps = kpb.div_ceil(KT);
                for ib in (0..m_pad).step_by(MB) {
                    let a = unsafe { apack.as_ptr().add(ib * KC_PAIRS) };
                    for j in 0..panels {
                        let b = unsafe { bpack.as_ptr().add(j * KC_PAIRS * NB) };
                        let cp = unsafe { c.as_mut_ptr().add(ib * n_pad + j * NB) };
                        unsafe { block(a, KC_PAIRS * 4, b, steps, cp, n_pad * 4, true) };
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
        dst.copy_from_slice(&partials[0][i * n_pad..i * n_pad + n]);
        for part in &partials[1..] {
            for (d, s) in dst.iter_mut().zip(&part[i * n_pad..i * n_pad + n]) {
                *d += s;
            }
        }
    });
}

/// The right operand as panels [panel][kpp pairs][32 columns], zero past k and n.
unsafe fn pack_b(n: usize, k: usize, kpp: usize, rhs: MatRef) -> Vec<u32> {
    let kp = k.div_ceil(2);
    let mut out = vec![0u32; n.div_ceil(NB) * kpp * NB];
    let base = SendPtr(out.as_mut_ptr());
    let pack = |p: usize| unsafe { pack_b_pair(n, 2 * p, k, kpp, rhs, base.get().add(p * NB)) };
    #[cfg(feature = "rayon")]
    if k * n >= 1 << 16 {
        use rayon::prelude::*;
        (0..kp).into_par_iter().with_min_len(64).for_each(pack);
        return out;
    }
    (0..kp).for_each(pack);
    out
}

/// Rows i0 .. i0 + rows, pairs p0 .. p1 of the left operand (k columns) as pair rows:
/// pair p of row i0 + r at `dst + r * stride + (p - p0)`. Row-contiguous operands are
/// converted row by row, column-contiguous ones (a transposed activation, the weight
/// gradient's left operand) 16 x 16 pairs at a time through a register transpose.
#[allow(clippy::too_many_arguments)]
pub(crate) unsafe fn pack_a(
    lhs: MatRef,
    i0: usize,
    rows: usize,
    p0: usize,
    p1: usize,
    k: usize,
    dst: *mut u32,
    stride: usize,
) {
    let k1 = (2 * p1).min(k);
    if lhs.cs == 1 {
        for r in 0..rows {
            let src = unsafe { lhs.at_ptr(i0 + r, 2 * p0) };
            unsafe { convert_row(src, k1 - 2 * p0, dst.add(r * stride)) };
        }
        return;
    }
    let mut r = 0;
    if lhs.rs == 1 {
        while r + 16 <= rows {
            let mut p = p0;
            while p + 16 <= p1 && 2 * p + 32 <= k {
                unsafe { transpose_pairs(lhs, i0 + r, p, dst.add(r * stride + (p - p0)), stride) };
                p += 16;
            }
            for rr in r..r + 16 {
                for q in p..p1 {
                    unsafe { *dst.add(rr * stride + (q - p0)) = pair_at(lhs, i0 + rr, q, k) };
                }
            }
            r += 16;
        }
    }
    for rr in r..rows {
        for q in p0..p1 {
            unsafe { *dst.add(rr * stride + (q - p0)) = pair_at(lhs, i0 + rr, q, k) };
        }
    }
}

/// Pair q of row i (k columns; the second half zero past k).
#[inline]
unsafe fn pair_at(lhs: MatRef, i: usize, q: usize, k: usize) -> u32 {
    let x0 = unsafe { lhs.at(i, 2 * q) };
    let x1 = if 2 * q + 1 < k { unsafe { lhs.at(i, 2 * q + 1) } } else { 0.0 };
    pair_bits(x0, x1)
}

/// Rows i .. i + 16 and pairs p .. p + 16 of a left operand with unit row stride (`lhs.rs ==
/// 1`): 16 pair vectors over the rows, transposed into 16 rows of 16 pairs at `dst`.
#[target_feature(enable = "avx512f,avx512bw,avx512bf16")]
unsafe fn transpose_pairs(lhs: MatRef, i: usize, p: usize, dst: *mut u32, stride: usize) {
    unsafe {
        // One conversion of both rows (x in the low half, y in the high), then one permute
        // into pairs (x_r, y_r).
        let interleave = _mm512_loadu_si512(PAIR_ORDER.0.as_ptr() as *const _);
        let mut v = [_mm512_setzero_si512(); 16];
        for (q, vq) in v.iter_mut().enumerate() {
            let s0 = lhs.at_ptr(i, 2 * (p + q));
            let s1 = s0.offset(lhs.cs);
            let xy = _mm512_cvtne2ps_pbh(_mm512_loadu_ps(s1), _mm512_loadu_ps(s0));
            *vq =
                _mm512_permutexvar_epi16(interleave, core::mem::transmute::<__m512bh, __m512i>(xy));
        }
        let t = transpose16(v);
        for (r, tr) in t.iter().enumerate() {
            _mm512_storeu_si512(dst.add(r * stride) as *mut _, *tr);
        }
    }
}

/// Transpose of a 16 x 16 matrix of u32 held as 16 rows.
#[target_feature(enable = "avx512f")]
#[inline]
fn transpose16(r: [__m512i; 16]) -> [__m512i; 16] {
    let mut t = [_mm512_setzero_si512(); 16];
    for j in 0..8 {
        t[2 * j] = _mm512_unpacklo_epi32(r[2 * j], r[2 * j + 1]);
        t[2 * j + 1] = _mm512_unpackhi_epi32(r[2 * j], r[2 * j + 1]);
    }
    // u[4j + q], lane L: column 4L + q of rows 4j .. 4j + 3.
    let mut u = [_mm512_setzero_si512(); 16];
    for j in 0..4 {
        u[4 * j] = _mm512_unpacklo_epi64(t[4 * j], t[4 * j + 2]);
        u[4 * j + 1] = _mm512_unpackhi_epi64(t[4 * j], t[4 * j + 2]);
        u[4 * j + 2] = _mm512_unpacklo_epi64(t[4 * j + 1], t[4 * j + 3]);
        u[4 * j + 3] = _mm512_unpackhi_epi64(t[4 * j + 1], t[4 * j + 3]);
    }
    let mut out = [_mm512_setzero_si512(); 16];
    for q in 0..4 {
        let x0 = _mm512_shuffle_i32x4::<0x44>(u[q], u[4 + q]);
        let x1 = _mm512_shuffle_i32x4::<0xEE>(u[q], u[4 + q]);
        let x2 = _mm512_shuffle_i32x4::<0x44>(u[8 + q], u[12 + q]);
        let x3 = _mm512_shuffle_i32x4::<0xEE>(u[8 + q], u[12 + q]);
        out[q] = _mm512_shuffle_i32x4::<0x88>(x0, x2);
        out[4 + q] = _mm512_shuffle_i32x4::<0xDD>(x0, x2);
        out[8 + q] = _mm512_shuffle_i32x4::<0x88>(x1, x3);
        out[12 + q] = _mm512_shuffle_i32x4::<0xDD>(x1, x3);
    }
    out
}
