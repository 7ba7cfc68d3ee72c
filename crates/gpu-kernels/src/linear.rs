//! A linear layer's five GPU operations on row-major f32 matrices ([`Matrix`]): the forward
//! product with the bias and ReLU fused, the input gradient `dY Wᵀ`, the weight gradient
//! `Xᵀ dY` (split-K over the batch), the bias gradient (column sums) and the ReLU backward.
//! Shapes are checked ([`ShapeError`] names the operation and the sizes); outputs are new
//! buffers. Every sum runs in an order fixed by the shapes alone, so the results are the same
//! bits on every run of one device.

use crate::{elementwise, gemm, reduce};
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

/// Operands whose shapes do not fit the operation.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ShapeError(pub String);

impl std::fmt::Display for ShapeError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for ShapeError {}

/// The batch length of one split of a weight gradient's sum (as `cpu-kernels`' split-k).
pub const SPLIT_LEN: u32 = 2048;
/// The most splits of one weight gradient.
pub const MAX_SPLITS: u32 = 64;
/// The most cubes along a grid axis the kernels launch (the limit of Vulkan and WebGPU).
const MAX_CUBES: u32 = 65_535;

fn check(ok: bool, what: impl FnOnce() -> String) -> Result<(), ShapeError> {
    if ok { Ok(()) } else { Err(ShapeError(what())) }
}

fn check_grid(op: &str, cubes: u32) -> Result<(), ShapeError> {
    check(cubes <= MAX_CUBES, || format!("{op}: {cubes} cubes along one axis exceed {MAX_CUBES}"))
}

/// `x W (+ bias) (ReLU)` for x `[rows, d_in]`, W `[d_in, d_out]`, bias `[d_out]`.
pub fn forward(
    client: &Client,
    x: &Matrix,
    w: &Matrix,
    bias: Option<&Handle>,
    relu: bool,
) -> Result<Matrix, ShapeError> {
    check(x.cols == w.rows, || {
        format!("linear forward: x is {} x {} but W is {} x {}", x.rows, x.cols, w.rows, w.cols)
    })?;
    check_grid("linear forward", x.rows.div_ceil(gemm::TILE))?;
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
    };
    let bias_handle = bias.cloned().unwrap_or_else(|| w.handle.clone());
    let bias_len = if bias.is_some() { w.cols as usize } else { 1 };
    // SAFETY: the shapes were checked against the matrices, whose buffers hold their elements.
    unsafe {
        gemm::launch_gemm(
            client,
            x.handle.clone(),
            w.handle.clone(),
            bias_handle,
            y.handle.clone(),
            [x.len(), w.len(), bias_len, y.len()],
            shape,
            1,
            epilogue,
        );
    }
    Ok(y)
}

/// The input gradient `dY Wᵀ` `[rows, d_in]` for W `[d_in, d_out]` and dY `[rows, d_out]`.
pub fn x_backward(client: &Client, w: &Matrix, dy: &Matrix) -> Result<Matrix, ShapeError> {
    check(dy.cols == w.cols, || {
        format!("input gradient: dY is {} x {} but W is {} x {}", dy.rows, dy.cols, w.rows, w.cols)
    })?;
    check_grid("input gradient", dy.rows.div_ceil(gemm::TILE))?;
    let dx = Matrix::empty(client, dy.rows, w.rows);
    let shape = gemm::GemmShape {
        m: dy.rows,
        n: w.rows,
        k: w.cols,
        a_strides: (dy.cols, 1),
        // Wᵀ (p, j) = W (j, p).
        b_strides: (1, w.cols),
    };
    // SAFETY: as in `forward`.
    unsafe {
        gemm::launch_gemm(
            client,
            dy.handle.clone(),
            w.handle.clone(),
            w.handle.clone(),
            dx.handle.clone(),
            [dy.len(), w.len(), 1, dx.len()],
            shape,
            1,
            gemm::Epilogue::None,
        );
    }
    Ok(dx)
}

/// The number of splits of a weight gradient's sum over `rows`: a function of `rows` alone.
pub fn splits(rows: u32) -> u32 {
    rows.div_ceil(SPLIT_LEN).clamp(1, MAX_SPLITS)
}

/// The weight gradient `Xᵀ dY` `[d_in, d_out]` for x `[rows, d_in]` and dY `[rows, d_out]`:
/// [`splits`] partial sums over blocks of rows, added in order.
pub fn weight_backward(client: &Client, x: &Matrix, dy: &Matrix) -> Result<Matrix, ShapeError> {
    check(x.rows == dy.rows, || {
        format!("weight gradient: x is {} x {} but dY is {} x {}", x.rows, x.cols, dy.rows, dy.cols)
    })?;
    let s = splits(x.rows);
    let shape = gemm::GemmShape {
        m: x.cols,
        n: dy.cols,
        k: x.rows,
        // Xᵀ (i, p) = X (p, i).
        a_strides: (1, x.cols),
        b_strides: (dy.cols, 1),
    };
    let dw = Matrix::empty(client, x.cols, dy.cols);
    let parts = if s == 1 { dw.clone() } else { Matrix::empty(client, s * x.cols, dy.cols) };
    // SAFETY: as in `forward`; `parts` holds `s` products.
    unsafe {
        gemm::launch_gemm(
            client,
            x.handle.clone(),
            dy.handle.clone(),
            dy.handle.clone(),
            parts.handle.clone(),
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

/// The bias gradient: dY `[rows, d_out]` summed over its rows, in blocks of [`SPLIT_LEN`] rows
/// added in order. Returns `d_out` floats.
pub fn bias_backward(client: &Client, dy: &Matrix) -> Result<Matrix, ShapeError> {
    let s = splits(dy.rows);
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
