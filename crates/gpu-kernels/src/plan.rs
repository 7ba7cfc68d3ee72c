//! The launch plan of the kernels, in plain Rust (no CubeCL, so it builds and is tested
//! without a GPU runtime): the tile a cube computes ([`Tiling`]), the operands' precision
//! ([`Precision`]) and which products take bf16 ([`takes_bf16`]), a layer's [`Tuning`], the
//! number of splits of a weight gradient and of blocks of a bias gradient (functions of the
//! shapes alone, so that every sum runs in a fixed order), and the [`ShapeError`] every
//! operation refuses with.

/// Units per cube along each axis.
pub const UNITS: u32 = 16;

/// The tile of C one cube computes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Tiling {
    /// 64 x 64, 4 x 4 sums a unit: many cubes for short or narrow products (the default).
    #[default]
    T64,
    /// 128 x 128, 8 x 8 sums a unit: twice the arithmetic per shared-memory read.
    T128,
    /// 64 x 64, 4 x 4 sums a unit in contiguous rows and columns, the slabs read from shared
    /// memory four floats at a time (`gemm_vec4`).
    T64V,
    /// 128 x 128, 8 x 8 sums a unit in two blocks of four contiguous rows and columns, the
    /// slabs read from shared memory four floats at a time (`gemm_vec4`).
    T128V,
}

impl Tiling {
    /// Every tiling (the tests run each).
    pub const ALL: [Tiling; 4] = [Tiling::T64, Tiling::T128, Tiling::T64V, Tiling::T128V];

    /// Rows and columns of C per cube.
    pub fn tile(self) -> u32 {
        UNITS * self.per_unit()
    }

    /// Rows and columns of sums per unit.
    pub fn per_unit(self) -> u32 {
        match self {
            Tiling::T64 | Tiling::T64V => 4,
            Tiling::T128 | Tiling::T128V => 8,
        }
    }
}

/// An operation that cannot run: operands whose shapes do not fit it, or a [`Precision`] the
/// device lacks. The message names the operation.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ShapeError(pub String);

/// The precision of a product's operands; its sums are f32 either way.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Precision {
    /// f32 operands, on every device and every [`Tiling`].
    #[default]
    F32,
    /// Operands rounded to bf16 (8 bits of mantissa), multiplied on tensor cores
    /// (`gemm_cmma`); only where `linear::bf16_supported` (CUDA on Ampere or later), and
    /// only for products large enough to gain ([`takes_bf16`]; the others run in f32). The
    /// tile is the kernel's own; [`Tuning::tiling`] does not apply.
    Bf16,
}

/// Whether an m x k by k x n product asked for in [`Precision::Bf16`] takes the tensor cores:
/// products that gain nothing (narrow outputs such as a 3-channel head, a short k, small
/// products) stay f32. The rule of the CPU's bf16 products (`cpu_kernels::takes_bf16`), so that
/// both train the same products in bf16.
pub fn takes_bf16(m: u32, n: u32, k: u32) -> bool {
    n >= 16 && k >= 8 && u64::from(m) * u64::from(n) * u64::from(k) >= 1 << 18
}

impl std::fmt::Display for ShapeError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for ShapeError {}

/// The cubes a weight gradient's launch aims for (tiles x splits): about two for each
/// multiprocessor of a large GPU (an H200 has 132), where one split per 2,048 rows left most of
/// them idle.
pub const TARGET_CUBES: u32 = 256;
/// The fewest batch rows one split sums (unless the batch is shorter).
pub const MIN_SPLIT_ROWS: u32 = 128;
/// The most splits of one weight gradient.
pub const MAX_SPLITS: u32 = 256;
/// The batch rows of one block of the bias gradient's first pass.
pub const BIAS_BLOCK_ROWS: u32 = 128;

/// How a layer's products are launched beyond their precision: the f32 tile, and the batch
/// length of every split of a weight gradient.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Tuning {
    /// The tile of the f32 products (default [`Tiling::T64`]).
    pub tiling: Tiling,
    /// A fixed batch length for every split of a weight gradient (`None`: the default rule of
    /// [`splits`]); [`Tuning::with_split_len`] checks it.
    pub split_len: Option<u32>,
}

impl Tuning {
    /// This tuning with every split of a weight gradient summing `len` batch rows (a power of
    /// two from 64 to 65,536), or `None` for the default rule of [`splits`]. The number of
    /// splits, and so the order of every sum, stays a function of the shapes and this value.
    ///
    /// # Errors
    /// A length outside that range.
    pub fn with_split_len(self, len: Option<u32>) -> Result<Tuning, ShapeError> {
        if let Some(len) = len {
            check(len.is_power_of_two() && (64..=65_536).contains(&len), || {
                format!("split length {len}: expected a power of two from 64 to 65536")
            })?;
        }
        Ok(Tuning { split_len: len, ..self })
    }
}

/// `Ok` where `ok` holds, else the [`ShapeError`] `what` describes.
pub(crate) fn check(ok: bool, what: impl FnOnce() -> String) -> Result<(), ShapeError> {
    if ok { Ok(()) } else { Err(ShapeError(what())) }
}

/// The number of splits of a weight gradient's sum over `rows` whose `[d_in, d_out]` output
/// takes `tiles` tiles: enough for [`TARGET_CUBES`] cubes in all, each split summing at least
/// [`MIN_SPLIT_ROWS`] rows, at most [`MAX_SPLITS`] (or `rows / len` for a fixed `split_len`,
/// [`Tuning::split_len`]). A function of the shapes (and that length) alone.
pub fn splits(rows: u32, tiles: u32, split_len: Option<u32>) -> u32 {
    match split_len {
        None | Some(0) => {
            let wanted = TARGET_CUBES.div_ceil(tiles.max(1));
            wanted.min(rows / MIN_SPLIT_ROWS).clamp(1, MAX_SPLITS)
        }
        Some(len) => rows.div_ceil(len).clamp(1, MAX_SPLITS),
    }
}

/// The blocks of the bias gradient's first pass over `rows`: one per [`BIAS_BLOCK_ROWS`]
/// rows, at most [`MAX_SPLITS`] (each of its units then sums at most a few hundred values in
/// either pass).
pub fn bias_blocks(rows: u32) -> u32 {
    rows.div_ceil(BIAS_BLOCK_ROWS).clamp(1, MAX_SPLITS)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The default rule fills the GPU; a fixed length is taken only when valid.
    #[test]
    fn split_counts_follow_the_rule_and_the_length() {
        // A 128 x 128 gradient on 64-wide tiles (4 tiles) at 2^15: 64 splits of 512 rows.
        assert_eq!(splits(32_768, 4, None), 64);
        assert_eq!(splits(32_768, 1, None), 256);
        assert_eq!(splits(8_192, 4, None), 64);
        assert_eq!(splits(1_000, 4, None), 7);
        assert_eq!(splits(1, 4, None), 1);
        assert_eq!(splits(100_000, 1_000, None), 1);
        assert_eq!(bias_blocks(32_768), 256);
        assert_eq!(bias_blocks(1), 1);
        for bad in [0, 1, 32, 100, 3000, 131_072] {
            let e = Tuning::default().with_split_len(Some(bad)).unwrap_err().to_string();
            assert!(e.contains(&bad.to_string()) && e.contains("power of two"), "{e}");
        }
        let t = Tuning::default().with_split_len(Some(2048)).unwrap();
        assert_eq!(splits(32_768, 4, t.split_len), 16);
        assert_eq!(splits(1, 4, t.split_len), 1);
        assert_eq!(t.with_split_len(None).unwrap(), Tuning::default());
        assert_eq!(Tuning::default().tiling, Tiling::T64);
    }
}
