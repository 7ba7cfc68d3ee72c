//! Sums in a fixed order, so that a result does not depend on how the GPU schedules its cubes:
//! `sum_parts` adds split-K's partial products (part 0, then 1, ...), and
//! `column_partial_sums` sums a matrix's columns over blocks of rows (the bias gradient,
//! `dY` summed over the batch), whose partials `sum_parts` then adds.

use cubecl::prelude::*;

/// Units per cube of the reductions.
pub const UNITS: u32 = 256;

/// `out[i] = parts[i] + parts[len + i] + ... + parts[(count - 1) len + i]`, in that order.
#[cube(launch, launch_unchecked)]
pub(crate) fn sum_parts(parts: &[f32], out: &mut [f32], count: u32, len: u32) {
    let i = ABSOLUTE_POS_X;
    if i < len {
        let mut s = 0.0f32;
        for p in 0..count {
            s += parts[(p * len + i) as usize];
        }
        out[i as usize] = s;
    }
}

/// `partials[p n + j]` = the sum of column j of the row-major m x n matrix `x` over rows
/// `p rows_per_part .. (p + 1) rows_per_part`, in row order. Launched on
/// `(ceil(n / 256), parts)` cubes of 256 units.
#[cube(launch, launch_unchecked)]
pub(crate) fn column_partial_sums(
    x: &[f32],
    partials: &mut [f32],
    m: u32,
    n: u32,
    rows_per_part: u32,
) {
    let j = ABSOLUTE_POS_X;
    let p = CUBE_POS_Y;
    if j < n {
        let start = p * rows_per_part;
        let end = select(m < start + rows_per_part, m, start + rows_per_part);
        let mut s = 0.0f32;
        for r in start..end {
            s += x[(r * n + j) as usize];
        }
        partials[(p * n + j) as usize] = s;
    }
}

/// Launches `sum_parts` over `count` parts of `len` floats.
///
/// # Safety
/// `parts` must hold `count * len` floats and `out` `len`.
pub unsafe fn launch_sum_parts(
    client: &Client,
    parts: cubecl::server::Handle,
    out: cubecl::server::Handle,
    count: u32,
    len: u32,
) {
    unsafe {
        crate::checks::launch!(
            sum_parts,
            client,
            CubeCount::Static(len.div_ceil(UNITS), 1, 1),
            CubeDim::new_1d(UNITS),
            BufferArg::from_raw_parts(parts, (count * len) as usize),
            BufferArg::from_raw_parts(out, len as usize),
            count,
            len,
        );
    }
}

/// Launches `column_partial_sums` with `parts` blocks of `ceil(m / parts)` rows.
///
/// # Safety
/// `x` must hold `m * n` floats and `partials` `parts * n`.
pub unsafe fn launch_column_partial_sums(
    client: &Client,
    x: cubecl::server::Handle,
    partials: cubecl::server::Handle,
    m: u32,
    n: u32,
    parts: u32,
) {
    let rows_per_part = m.div_ceil(parts.max(1)).max(1);
    unsafe {
        crate::checks::launch!(
            column_partial_sums,
            client,
            CubeCount::Static(n.div_ceil(UNITS), parts.max(1), 1),
            CubeDim::new_1d(UNITS),
            BufferArg::from_raw_parts(x, (m * n) as usize),
            BufferArg::from_raw_parts(partials, (parts.max(1) * n) as usize),
            m,
            n,
            rows_per_part,
        );
    }
}
