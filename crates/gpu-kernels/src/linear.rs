//! A linear layer's five GPU operations on row-major f32 matrices ([`Matrix`]): the forward
//! product with the bias and ReLU fused, the input gradient `dY Wᵀ`, the weight gradient
//! `Xᵀ dY` (split-K over the batch), the bias gradient (column sums) and the ReLU backward.
//! Shapes are checked ([`ShapeError`] names the operation and the sizes); outputs are new
//! buffers. Every sum runs in an order fixed by the shapes alone, so the results are the same
//! bits on every run of one device. The three products take a [`Precision`]: f32 operands on
//! the tiled kernels of [`crate::gemm`], or bf16 operands on tensor cores
//! ([`crate::gemm_cmma`], where the device has them; sums in f32 either way), and a [`Tuning`]:
//! the f32 tile and the weight gradient's split length. Both are arguments of every call,
//! never a per-thread or per-process setting, so a product's arguments say everything that
//! decides its value.

use crate::plan::{Precision, ShapeError, Tiling, Tuning, bias_blocks, check, splits, takes_bf16};
use crate::{elementwise, gemm, gemm_cmma, reduce};
use cubecl::prelude::*;
use cubecl::server::Handle;

/// A row-major `rows x cols` f32 matrix on the device.
#[derive(Clone, Debug)]
pub struct Matrix {
    /// The buffer (at least `rows * cols` floats).
    pub handle: Handle,
    /// Rows.
    pub rows: u32,
    /// Columns.
    pub cols: u32,
}

impl Matrix {
    /// Uploads `values` (row-major, `rows * cols` of them).
    pub fn upload(
        client: &Client,
        values: &[f32],
        rows: u32,
        cols: u32,
    ) -> Result<Self, ShapeError> {
        if values.len() != rows as usize * cols as usize {
            return Err(ShapeError(format!(
                "upload: {} values for a {rows} x {cols} matrix",
                values.len()
            )));
        }
        Ok(Self { handle: client.create_from_slice(f32::as_bytes(values)), rows, cols })
    }

    /// An uninitialised matrix.
    pub fn empty(client: &Client, rows: u32, cols: u32) -> Self {
        let bytes = (rows as usize * cols as usize).max(1) * size_of::<f32>();
        Self { handle: client.empty(bytes), rows, cols }
    }

    /// Reads the matrix back (row-major).
    pub fn read(&self, client: &Client) -> Vec<f32> {
        let bytes = client.read_one_unchecked(self.handle.clone());
        f32::from_bytes(&bytes)[..self.len()].to_vec()
    }

    fn len(&self) -> usize {
        self.rows as usize * self.cols as usize
    }
}

/// Whether `client`'s device runs [`Precision::Bf16`] products.
pub fn bf16_supported(client: &Client) -> bool {
    gemm_cmma::bf16_supported(client)
}

/// The precision an m x k by k x n product asked for in `precision` runs in ([`takes_bf16`]).
fn effective(precision: Precision, m: u32, n: u32, k: u32) -> Precision {
    match precision {
        Precision::Bf16 if takes_bf16(m, n, k) => Precision::Bf16,
        _ => Precision::F32,
    }
}

/// The tile of C one cube computes for a product in `precision` on `tiling`.
fn tile_of(precision: Precision, tiling: Tiling) -> u32 {
    match precision {
        Precision::F32 => tiling.tile(),
        Precision::Bf16 => gemm_cmma::TILE,
    }
}

/// Refuses `precision` where the device cannot run it.
fn check_precision(client: &Client, op: &str, precision: Precision) -> Result<(), ShapeError> {
    check(precision == Precision::F32 || bf16_supported(client), || {
        format!(
            "{op}: bf16 products need tensor cores that multiply bf16 fragments (CubeCL's cmma, \
             16 x 16 x 16 into f32: CUDA on Ampere or later), and this device has none"
        )
    })
}

/// Launches the product `c = a b` of `shape` in `precision` (see [`gemm::launch_gemm`]).
///
/// # Safety
/// As [`gemm::launch_gemm`]; `precision` checked with [`check_precision`].
#[allow(clippy::too_many_arguments)]
unsafe fn launch_product(
    client: &Client,
    precision: Precision,
    handles: [Handle; 4],
    lens: [usize; 4],
    shape: gemm::GemmShape,
    splits: u32,
    epilogue: gemm::Epilogue,
) {
    let [a, b, bias, c] = handles;
    // SAFETY: the caller's.
    unsafe {
        match precision {
            Precision::F32 => {
                gemm::launch_gemm(client, a, b, bias, c, lens, shape, splits, epilogue);
            }
            Precision::Bf16 => {
                gemm_cmma::launch_gemm_cmma(client, a, b, bias, c, lens, shape, splits, epilogue);
            }
        }
    }
}

/// The most cubes along a grid axis the kernels launch (the limit of Vulkan and WebGPU).
pub(crate) const MAX_CUBES: u32 = 65_535;

fn check_grid(op: &str, cubes: u32) -> Result<(), ShapeError> {
    check(cubes <= MAX_CUBES, || format!("{op}: {cubes} cubes along one axis exceed {MAX_CUBES}"))
}

/// `x W (+ bias) (ReLU)` for x `[rows, d_in]`, W `[d_in, d_out]`, bias `[d_out]`, the product
/// in `precision` on `tuning`'s tile.
#[allow(clippy::too_many_arguments)]
pub fn forward(
    client: &Client,
    x: &Matrix,
    w: &Matrix,
    bias: Option<&Handle>,
    relu: bool,
    precision: Precision,
    tuning: Tuning,
) -> Result<Matrix, ShapeError> {
    check(x.cols == w.rows, || {
        format!("linear forward: x is {} x {} but W is {} x {}", x.rows, x.cols, w.rows, w.cols)
    })?;
    check_precision(client, "linear forward", precision)?;
    let precision = effective(precision, x.rows, w.cols, x.cols);
    let tiling = tuning.tiling;
    check_grid("linear forward", x.rows.div_ceil(tile_of(precision, tiling)))?;
    let y = Matrix::empty(client, x.rows, w.cols);
    let epilogue = match (bias.is_some(), relu) {
        (false, false) => gemm::Epilogue::None,
        (true, false) => gemm::Epilogue::Bias,
        (true, true) => gemm::Epilogue::BiasRelu,
        (false, true) => {
            return Err(ShapeError("linear forward: a fused ReLU needs a bias".into()));
        }
    };
    let shape = gemm::GemmShape {
        m: x.rows,
        n: w.cols,
        k: x.cols,
        a_strides: (x.cols, 1),
        b_strides: (w.cols, 1),
        tiling,
    };
    let bias_handle = bias.cloned().unwrap_or_else(|| w.handle.clone());
    let bias_len = if bias.is_some() { w.cols as usize } else { 1 };
    // SAFETY: the shapes were checked against the matrices, whose buffers hold their elements.
    unsafe {
        launch_product(
            client,
            precision,
            [x.handle.clone(), w.handle.clone(), bias_handle, y.handle.clone()],
            [x.len(), w.len(), bias_len, y.len()],
            shape,
            1,
            epilogue,
        );
    }
    Ok(y)
}

/// The input gradient `dY Wᵀ` `[rows, d_in]` for W `[d_in, d_out]` and dY `[rows, d_out]`, in
/// `precision` on `tuning`'s tile.
pub fn x_backward(
    client: &Client,
    w: &Matrix,
    dy: &Matrix,
    precision: Precision,
    tuning: Tuning,
) -> Result<Matrix, ShapeError> {
    check(dy.cols == w.cols, || {
        format!("input gradient: dY is {} x {} but W is {} x {}", dy.rows, dy.cols, w.rows, w.cols)
    })?;
    check_precision(client, "input gradient", precision)?;
    let precision = effective(precision, dy.rows, w.rows, w.cols);
    let tiling = tuning.tiling;
    check_grid("input gradient", dy.rows.div_ceil(tile_of(precision, tiling)))?;
    let dx = Matrix::empty(client, dy.rows, w.rows);
    let shape = gemm::GemmShape {
        m: dy.rows,
        n: w.rows,
        k: w.cols,
        a_strides: (dy.cols, 1),
        // Wᵀ (p, j) = W (j, p).
        b_strides: (1, w.cols),
        tiling,
    };
    // SAFETY: as in `forward`.
    unsafe {
        launch_product(
            client,
            precision,
            [dy.handle.clone(), w.handle.clone(), w.handle.clone(), dx.handle.clone()],
            [dy.len(), w.len(), 1, dx.len()],
            shape,
            1,
            gemm::Epilogue::None,
        );
    }
    Ok(dx)
}

/// The weight gradient `Xᵀ dY` `[d_in, d_out]` for x `[rows, d_in]` and dY `[rows, d_out]`:
/// [`splits`] partial sums over blocks of rows (products in `precision` on `tuning`'s tile and
/// split length), added in order (f32).
pub fn weight_backward(
    client: &Client,
    x: &Matrix,
    dy: &Matrix,
    precision: Precision,
    tuning: Tuning,
) -> Result<Matrix, ShapeError> {
    check(x.rows == dy.rows, || {
        format!("weight gradient: x is {} x {} but dY is {} x {}", x.rows, x.cols, dy.rows, dy.cols)
    })?;
    check_precision(client, "weight gradient", precision)?;
    let precision = effective(precision, x.cols, dy.cols, x.rows);
    let tiling = tuning.tiling;
    let tile = tile_of(precision, tiling);
    let s = splits(x.rows, x.cols.div_ceil(tile) * dy.cols.div_ceil(tile), tuning.split_len);
    let shape = gemm::GemmShape {
        m: x.cols,
        n: dy.cols,
        k: x.rows,
        // Xᵀ (i, p) = X (p, i).
        a_strides: (1, x.cols),
        b_strides: (dy.cols, 1),
        tiling,
    };
    let dw = Matrix::empty(client, x.cols, dy.cols);
    let parts = if s == 1 { dw.clone() } else { Matrix::empty(client, s * x.cols, dy.cols) };
    // SAFETY: as in `forward`; `parts` holds `s` products.
    unsafe {
        launch_product(
            client,
            precision,
            [x.handle.clone(), dy.handle.clone(), dy.handle.clone(), parts.handle.clone()],
            [x.len(), dy.len(), 1, parts.len()],
            shape,
            s,
            gemm::Epilogue::None,
        );
        if s > 1 {
            reduce::launch_sum_parts(
                client,
                parts.handle.clone(),
                dw.handle.clone(),
                s,
                x.cols * dy.cols,
            );
        }
    }
    Ok(dw)
}

/// The bias gradient: dY `[rows, d_out]` summed over its rows, in [`bias_blocks`] blocks of
/// rows added in order. Returns `d_out` floats.
pub fn bias_backward(client: &Client, dy: &Matrix) -> Result<Matrix, ShapeError> {
    let s = bias_blocks(dy.rows);
    check_grid("bias gradient", dy.cols.div_ceil(reduce::UNITS))?;
    let db = Matrix::empty(client, 1, dy.cols);
    let parts = if s == 1 { db.clone() } else { Matrix::empty(client, s, dy.cols) };
    // SAFETY: `dy` holds rows x cols floats, `parts` s x cols.
    unsafe {
        reduce::launch_column_partial_sums(
            client,
            dy.handle.clone(),
            parts.handle.clone(),
            dy.rows,
            dy.cols,
            s,
        );
        if s > 1 {
            reduce::launch_sum_parts(client, parts.handle.clone(), db.handle.clone(), s, dy.cols);
        }
    }
    Ok(db)
}

/// The ReLU's backward pass: `grad` where `x` was positive (or NaN), 0 elsewhere.
pub fn relu_backward(client: &Client, x: &Matrix, grad: &Matrix) -> Result<Matrix, ShapeError> {
    check(x.rows == grad.rows && x.cols == grad.cols, || {
        format!(
            "ReLU backward: x is {} x {} but the gradient {} x {}",
            x.rows, x.cols, grad.rows, grad.cols
        )
    })?;
    let len = u32::try_from(x.len())
        .map_err(|_| ShapeError("ReLU backward: too many elements".into()))?;
    check_grid("ReLU backward", len.div_ceil(elementwise::UNITS))?;
    let out = Matrix::empty(client, x.rows, x.cols);
    // SAFETY: the three buffers hold `len` floats.
    unsafe {
        elementwise::launch_relu_backward(
            client,
            x.handle.clone(),
            grad.handle.clone(),
            out.handle.clone(),
            len,
        );
    }
    Ok(out)
}
